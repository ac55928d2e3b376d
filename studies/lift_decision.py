"""What the day's lift decision sees on simulated cases: the fraction of the probe's lift the day's cost
prefers, and the gain in cost there with its jackknife sigma, for the day and for each FOV row (ahead,
centre, behind), beside the case's truth (its cloud law, edges, the footprint's full width at half peak).
The rule (:func:`monitor.estimation.parallax.keeps`) keeps a lift of at least 50 m/K where the day
gains more than 1 sigma; the rows' gains are what a rule by rows would see (docs/science.md, "What the
day's cost cannot tell apart"). Prints one JSON row per case. With ``--offsets`` the row also holds what
the day's estimate makes of the case against its truth, as the default configuration assesses it and
with ``parallax=False`` (from the same collocation): per direction the FOR offsets' RMS and worst error,
the share of FOR-directions within 2 sigma, the rms of error / sigma over them ("rms_z"), the median
sigma, the mean cross-track error of FORs 1-10 and 21-30 ("ends_beta_urad": the pattern a rendering
common to every granule bends into them) and each FOR's cross-track error and sigma ("beta_error_urad",
"beta_sigma_urad", FOR 1 first), and the rows' median error, share within 2
sigma and median sigma (the bounds of benchmarks.acceptance). With ``--at-lift`` as well, a second
pass: the case collocated again with the pixels rendered at the lift the default kept, and assessed
from that rendering alone (``parallax=False`` on it: f held at 1, no lift sigma), the row's
"at_lift" (docs/science.md, "One rendering at the day's lift"); with ``--at-law`` the same pass at the
lift the case's law implies (:func:`monitor.simulate.case.law_m_per_k`, in m per K of band BT), the
row's "at_law": what the offsets and the rows would read with the day's lift known.

    .venv/bin/python -m studies.lift_decision CASE_DIR... [--workers 2]
        [--offsets [--at-lift] [--at-law] | --probe M_PER_K] [--rows FILE]

``--probe`` renders the collocation at another lift than the assessment's: the fraction the day prefers
is of the blend V0 + f (V1 - V0), so what it prefers in m/K depends on the probe (docs/science.md, "The
lift decision on held-back days").

A case directory is one ``crisgeo simulate`` (or ``benchmarks.acceptance --keep``) wrote, with truth.json.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.estimates import cost_and_offsets, for_samples, paired
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR
from monitor.core.result import AssessmentResult
from monitor.estimation import parallax
from monitor.estimation.jackknife import granule_runs, jackknife_sigma
from monitor.instrument.spectral import i5_band
from monitor.simulate.case import law_m_per_k
from studies.collocated import collocated

ROW_NAMES = ("ahead", "centre", "behind")  # parallax.ROWS


def decision(
    case: Path,
    workers: int,
    offsets: bool = False,
    probe_m_per_k: float = PROBE_M_PER_K,
    at_lift: bool = False,
    at_law: bool = False,
) -> dict:
    """The row of one case (module docstring), its rendered collocation at *probe_m_per_k*."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig(workers=workers)
    samples = collocated(case, cfg, workers, probe_m_per_k)
    pairs = paired(samples)
    band = i5_band(truth["satellite"])
    cones = [
        parallax.matched_cone(
            for_samples(pairs[0], k, cfg, band), for_samples(pairs[1], k, cfg, band), cfg.cost
        )
        for k in range(N_FOR)
    ]
    s0, s1 = [a for a, _ in cones], [b for _, b in cones]
    f = parallax.day_fraction(s0, s1, cfg.cost)
    runs = granule_runs(np.unique(np.concatenate([a.granule for a in s0])))
    gain = parallax.row_costs(s0, s1, 0.0, cfg.cost) - parallax.row_costs(s0, s1, f, cfg.cost)
    gain_g = np.array(
        [
            parallax.row_costs(s0, s1, 0.0, cfg.cost, g) - parallax.row_costs(s0, s1, f, cfg.cost, g)
            for g in runs
        ]
    )
    sigma = [jackknife_sigma(gain_g[:, r]) for r in range(len(parallax.ROWS))]
    kept, _ = parallax.day_lift(s0, s1, cfg.cost, probe_m_per_k)
    row = {
        **case_fields(case, truth),
        "granules": len(runs),
        "law_m_per_k": law_m_per_k(truth["satellite"], truth.get("cloud_heights", "ground")),
        "fov_rows_alpha_urad": truth.get("fov_rows_alpha_urad", 0.0),
        "probe_m_per_k": probe_m_per_k,
        "preferred_m_per_k": round(f * probe_m_per_k, 1),
        "sigma_preferred_m_per_k": round(
            jackknife_sigma(np.array([parallax.day_fraction(s0, s1, cfg.cost, g, near=f) for g in runs]))
            * probe_m_per_k,
            1,
        ),
        "day_gain_sigmas": round(float(gain.sum() / jackknife_sigma(gain_g.sum(axis=1))), 1),
        "kept_m_per_k": round(kept * probe_m_per_k, 1),
    }
    for name, g, s in zip(ROW_NAMES, gain, sigma, strict=True):
        row[f"{name}_gain_sigmas"] = round(float(g / s), 1)
    if offsets:
        plain = cfg.model_copy(update={"parallax": False})
        default = cost_and_offsets(samples, cfg, satellite=truth["satellite"])
        row["default"] = scores(default, truth)
        row["no_parallax"] = scores(cost_and_offsets(pairs[0], plain, satellite=truth["satellite"]), truth)
        passes = {
            "at_lift": default.fors[0].parallax_m_per_k if at_lift else np.nan,
            "at_law": row["law_m_per_k"] if at_law and row["law_m_per_k"] is not None else np.nan,
        }
        for name, lift in passes.items():
            if np.isfinite(lift) and lift > 0:
                again = collocated(case, cfg, workers, lift)
                at = cost_and_offsets(paired(again)[1], plain, satellite=truth["satellite"])
                row[name] = scores(at, truth) | {"lift_m_per_k": round(float(lift), 1)}
    return row


def case_fields(case: Path, truth: dict) -> dict:
    """The fields that name a case's row: the commit, the case and its truth's clouds and footprint."""
    return {
        "commit": commit(),
        "case": case.name,
        "clouds": truth.get("cloud_heights", "ground"),
        "edges": truth.get("cloud_edges", "soft"),
        "footprint_width50_deg": None  # None: the paper's top-hat cone
        if truth.get("cris_response") is None
        else round(truth["cris_response"][0]["full_width_deg"]["50%"], 3),
    }


def scores(result: AssessmentResult, truth: dict) -> dict:
    """The day's errors against *truth* (module docstring), in-track and cross-track pairs."""
    fors = result.fors
    err = np.array([[f.d_alpha_urad - t["d_alpha_urad"], f.d_beta_urad - t["d_beta_urad"]]
                    for f, t in zip(fors, truth["fors"], strict=True)])  # fmt: skip
    sigma = np.array([[f.sigma_alpha_urad, f.sigma_beta_urad] for f in fors])
    rows = np.array([f.fov_rows_alpha_urad for f in fors]) - truth.get("fov_rows_alpha_urad", 0.0)
    rows_sigma = np.array([f.sigma_fov_rows_alpha_urad for f in fors])
    return {
        "lift_m_per_k": round(float(fors[0].parallax_m_per_k), 1),
        "rms_urad": np.sqrt(np.nanmean(err**2, axis=0)).round(1).tolist(),
        "worst_urad": np.nanmax(np.abs(err), axis=0).round(1).tolist(),
        "within_2_sigma": round(float(np.mean(np.abs(err) <= 2 * sigma)), 2),
        "rms_z": round(float(np.sqrt(np.nanmean((err / sigma) ** 2))), 2),
        "ends_beta_urad": [round(float(np.nanmean(err[s, 1])), 1) for s in (slice(0, 10), slice(20, 30))],
        "beta_error_urad": err[:, 1].round(1).tolist(),
        "beta_sigma_urad": sigma[:, 1].round(1).tolist(),
        "median_sigma_urad": np.nanmedian(sigma, axis=0).round(1).tolist(),
        "rows_median_error_urad": round(float(np.nanmedian(rows)), 1),
        "rows_within_2_sigma": round(float(np.mean(np.abs(rows) <= 2 * rows_sigma)), 2),
        "rows_median_sigma_urad": round(float(np.nanmedian(rows_sigma)), 1),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", type=Path)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--offsets", action="store_true", help="also the day's errors, default and parallax=False")
    p.add_argument(
        "--probe",
        type=float,
        default=PROBE_M_PER_K,
        help=f"the rendered collocation's lift, m/K (the assessment's {PROBE_M_PER_K:g}; not with --offsets)",
    )
    p.add_argument(
        "--at-lift", action="store_true", help="with --offsets: also a second pass rendered at the lift kept"
    )
    p.add_argument(
        "--at-law", action="store_true", help="with --offsets: also a pass rendered at the case's law"
    )
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    if args.offsets and args.probe != PROBE_M_PER_K:
        p.error("--offsets assesses as the service does, at its own probe: give --probe without it")
    for flag in ("at_lift", "at_law"):
        if getattr(args, flag) and not args.offsets:
            p.error(f"--{flag.replace('_', '-')} compares offsets: give it with --offsets")
    for case in args.cases:
        emit(decision(case, args.workers, args.offsets, args.probe, args.at_lift, args.at_law), args.rows)


if __name__ == "__main__":
    main()
