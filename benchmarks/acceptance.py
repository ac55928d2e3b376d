"""Full-size acceptance runs of the science core: recovery of injected offsets, and the uncertainty's
calibration.

For each case size, profile (paper, random, zero), ground (flat, or 1-4 km terrain over 40 % land), pass
(day: ascending; night: descending; also arctic, antarctic, and dateline = a night pass across 180 deg)
and seed: simulate, assess, and print per direction the RMS and the largest error over the 30 FORs against
the bounds (14 granules: RMS <= 10 urad, every FOR within 25; 6 granules and fewer: RMS <= 12, within 30).

The CrIS footprint of the truth (``--footprints``, :mod:`monitor.instrument.footprint`): the paper's top-hat
cone, or a smooth response within the specification's table; ``--kernel`` the assessment's (``footprint``, the
default, fits the response; ``top-hat`` is the paper's cone).

The reported sigma (derived: :mod:`monitor.estimation.jackknife`, nothing fitted to these cases) against
the errors: over all cases, the share of FOR-directions whose |error| <= 2 sigma (target >= 90 %) and, per
case, the median sigma over the RMS error (target <= 1.5).
CrIS-VIIRS calibration differences (``--mismatch``): the CrIS BT departs from VIIRS's by a gain
about 280 K, a bias and a curvature (:data:`MISMATCHES`); ``--cost`` picks the cost (assessment.cost). Each
row also holds the intercalibration recovered per FOR (bias at 280 K, gain), printed against the injected
values (every reliable FOR within 0.05 K and 0.2 %; the curvature printed).

Slow (~2-5 min per 14-granule case); not part of the test suite. ``--rows FILE`` appends one JSON line per
case and resumes from the cases already in the file; ``studies/rows/acceptance_2026-11-22.jsonl`` holds
the 25 cases of 2026-11-22 (print their tables with ``--from-rows``).

    .venv/bin/python benchmarks/acceptance.py [--sizes 14 6] [--seeds 1 2] [--profiles paper random zero]
        [--ground flat terrain] [--passes day night] [--mismatch none gain+3 ...] [--cost regression]
        [--footprints top-hat super-gaussian ...] [--kernel footprint] [--keep DIR] [--rows FILE]
"""

from __future__ import annotations

import argparse
import itertools
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit
from monitor.assessment.assess import assess_paths
from monitor.config.assessment import AssessmentConfig
from monitor.core.vocabulary import DEFAULT_COST, DEFAULT_KERNEL, Cost, Kernel
from monitor.instrument import footprint
from monitor.simulate.case import simulate_case
from monitor.simulate.scene import EDGES
from monitor.simulate.sun_synchronous import PASSES

# name: (gain, bias K, curvature K at 250/310 K) of CrIS against VIIRS (SimulationSpec.cris_*): the
# range, gains -3..+3 %, biases up to 2 K, curvatures up to 0.5 K over 250-310 K
MISMATCHES = {
    "none": (0.0, 0.0, 0.0),
    "gain+3": (0.03, 0.0, 0.0),
    "gain-3,bias+1.5": (-0.03, 1.5, 0.0),
    "gain+1,curve+0.5": (0.01, 0.0, 0.5),
    "bias+2,curve-0.5": (0.0, 2.0, -0.5),
    "gain-1,bias-2": (-0.01, -2.0, 0.0),
}
RECOVERY = (0.05, 0.2)  # the intercalibration's bound: bias K, gain per cent
NO_DIFFERENCE = (0.03, 0.1)  # where none was injected
BOUNDS = {14: (10.0, 25.0)}  # granules: (RMS, worst FOR) urad; smaller cases get SMALL_BOUNDS
SMALL_BOUNDS = (12.0, 30.0)
EXTRA_PASSES = {"dateline": ("night", 180.0)}


def run_case(
    root: Path,
    size: int,
    profile: str,
    ground: str,
    pass_name: str,
    seed: int,
    workers: int,
    keep: bool,
    mismatch: str = "none",
    cost: str = DEFAULT_COST.value,
    shape: str = "top-hat",
    kernel: str = DEFAULT_KERNEL.value,
    clouds: str = "ground",
    rows_urad: float = 0.0,
    edges: str = "soft",
    parallax: bool = True,
    wind_m_s: float = 0.0,
    emissivity: float = 1.0,
) -> dict:
    orbit_pass, lon = EXTRA_PASSES.get(pass_name, (pass_name, None))
    gain, bias_k, curve_k = MISMATCHES[mismatch]
    name = f"{profile}_{ground}_{pass_name}_{seed}_{size}_{mismatch}_{shape}_{clouds}_{rows_urad:g}"
    weather = ("" if edges == "soft" else f"_{edges}") + (f"_wind{wind_m_s:g}" if wind_m_s else "")
    case = root / (name + weather + (f"_e{emissivity:g}" if emissivity != 1.0 else ""))
    if keep and (case / "truth.json").exists():  # a kept case is assessed again, not simulated again
        truth = json.loads((case / "truth.json").read_text())
    else:
        truth = simulate_case(
            case,
            granules=size,
            profile=profile,
            seed=seed,
            terrain=ground == "terrain",
            orbit_pass=orbit_pass,
            pass_lon_deg=lon,
            cris_gain=gain,
            cris_bias_k=bias_k,
            cris_nonlinear_k=curve_k,
            cris_response=None if shape == "top-hat" else footprint.shape(shape),
            cloud_heights=clouds,
            cloud_edges=edges,
            fov_rows_alpha_urad=rows_urad,
            wind_in_track_m_s=wind_m_s,
            cloud_emissivity=emissivity,
        )
    t0 = time.perf_counter()
    cfg = AssessmentConfig(cost=Cost(cost), kernel=Kernel(kernel), parallax=parallax)
    result = assess_paths([case], cfg, workers=workers)
    secs = time.perf_counter() - t0
    (case / "result.json").write_text(result.to_json(with_cube=False))
    if not keep:
        shutil.rmtree(case)
    ta = np.array([f["d_alpha_urad"] for f in truth["fors"]])
    tb = np.array([f["d_beta_urad"] for f in truth["fors"]])
    return {
        "commit": commit(),
        "size": size,
        "profile": profile,
        "ground": ground,
        "pass": pass_name,
        "seed": seed,
        "assess_s": secs,
        "sigma_note": result.notes[-1] if result.notes else "",
        "err_alpha_urad": (np.array([f.d_alpha_urad for f in result.fors]) - ta).tolist(),
        "err_beta_urad": (np.array([f.d_beta_urad for f in result.fors]) - tb).tolist(),
        "sigma_alpha_urad": [f.sigma_alpha_urad for f in result.fors],
        "sigma_beta_urad": [f.sigma_beta_urad for f in result.fors],
        "reliable": [f.reliable for f in result.fors],
        "mismatch": mismatch,
        "cost": cost,
        "footprint": shape,
        "kernel": kernel,
        "bias_k": [f.bias_k for f in result.fors],
        "sigma_bias_k": [f.sigma_bias_k for f in result.fors],
        "gain_pct": [f.gain_pct for f in result.fors],
        "sigma_gain_pct": [f.sigma_gain_pct for f in result.fors],
        "curvature_k": [f.curvature_k for f in result.fors],
        "sigma_curvature_k": [f.sigma_curvature_k for f in result.fors],
        "clouds": clouds,
        "edges": edges,
        "parallax": parallax,
        "wind_in_track_m_s": wind_m_s,
        "cloud_emissivity": emissivity,
        "parallax_m_per_k": result.fors[0].parallax_m_per_k,
        "fov_rows_alpha_urad": rows_urad,
        "rows_err_alpha_urad": [f.fov_rows_alpha_urad - rows_urad for f in result.fors],
        "rows_err_beta_urad": [f.fov_rows_beta_urad for f in result.fors],
        "sigma_rows_alpha_urad": [f.sigma_fov_rows_alpha_urad for f in result.fors],
        "sigma_rows_beta_urad": [f.sigma_fov_rows_beta_urad for f in result.fors],
    }


def _key(r: dict) -> tuple:
    return (
        r["size"],
        r["ground"],
        r["pass"],
        r["profile"],
        r["seed"],
        r.get("mismatch", "none"),
        r.get("cost", "stdev"),
        r.get("footprint", "top-hat"),
        r.get("kernel", "top-hat"),
        r.get("clouds", "ground"),
        r.get("fov_rows_alpha_urad", 0.0),
        r.get("edges", "soft"),
        r.get("parallax", True),
        r.get("wind_in_track_m_s", 0.0),
        r.get("cloud_emissivity", 1.0),
    )


def recovery(row: dict) -> str:
    """The intercalibration of a row against the injected values: how many reliable FORs determine a gain
    (intercal.GAIN_RESOLUTION_PCT), and over those the median and worst bias and gain (bounded by RECOVERY,
    NO_DIFFERENCE where none was injected) and curvature (where the row has it)."""
    if "bias_k" not in row:
        return ""
    gain, bias_k, curve_k = MISMATCHES[row["mismatch"]]
    bounds = NO_DIFFERENCE if row["mismatch"] == "none" else RECOVERY
    ok = np.array(row["reliable"])
    determined = ok & np.isfinite(np.array(row["gain_pct"], float))
    parts, within = [f"gain at {determined.sum()}/{ok.sum()}"], determined.any()
    for name, injected, unit, bound in (
        ("bias_k", bias_k, "K", bounds[0]),
        ("gain_pct", 100 * gain, "%", bounds[1]),
        ("curvature_k", curve_k, "K", None),
    ):
        if name not in row or not determined.any():
            continue
        e = np.array(row[name], float)[determined] - injected
        worst = e[np.nanargmax(np.abs(e))]
        parts.append(f"{name.split('_')[0]} {np.nanmedian(e):+.3f} (worst {worst:+.3f}) {unit}")
        within &= bound is None or abs(worst) <= bound
    return "  " + ", ".join(parts) + ("  within" if within else "  OUT")


def verdict(row: dict) -> tuple[bool, str]:
    ea, eb = np.array(row["err_alpha_urad"]), np.array(row["err_beta_urad"])
    rms_max, abs_max = BOUNDS.get(row["size"], SMALL_BOUNDS)
    rms = np.sqrt(np.nanmean(ea**2)), np.sqrt(np.nanmean(eb**2))
    worst = np.nanmax(np.abs(ea)), np.nanmax(np.abs(eb))
    ok = bool(max(rms) <= rms_max and max(worst) <= abs_max and np.all(np.isfinite(ea + eb)))
    line = (
        f"{row.get('footprint', 'top-hat'):<14} {row.get('kernel', 'top-hat'):<9} "
        f"{row.get('mismatch', 'none'):<17} {row.get('cost', 'stdev'):<10} "
        f"{row['profile']:<7} {row['ground']:<8} {row['pass']:<9} {row['seed']:>4} {row['size']:>4} "
        f"{rms[0]:6.1f} {worst[0]:6.1f} {rms[1]:6.1f} {worst[1]:6.1f} {row['reliable'].count(False):>7} "
        f"{row['assess_s']:8.1f}  {'pass' if ok else 'FAIL'}{recovery(row)}{rows_read(row)}"
    )
    return ok, line


def rows_read(row: dict) -> str:
    """How the FOV rows' product reads the injected row error (ahead minus behind, in-track; none
    cross-track): per direction the median error and the share of FORs within 2 sigma (>= 90 %,
    median within 40 urad, median sigma <= 60 urad)."""
    if "rows_err_alpha_urad" not in row:
        return ""
    parts = []
    for d in ("alpha", "beta"):
        e = np.array(row[f"rows_err_{d}_urad"], float)
        s = np.array(row[f"sigma_rows_{d}_urad"], float)
        within = 100 * np.mean(np.abs(e) <= 2 * s)
        parts.append(f"{d} {np.nanmedian(e):+.0f} ({within:.0f}% in 2s, s {np.nanmedian(s):.0f})")
    return f"  rows {row['clouds']} {row['fov_rows_alpha_urad']:+g}: " + ", ".join(parts)


def calibration(rows: list[dict]) -> str:
    """The uncertainty table: coverage of 2 sigma and median sigma / RMS error, per case size."""
    lines = [f"{'gran':>4} {'cases':>5} {'|e|<=2s':>8} {'med s/rms':>10} {'worst s/rms':>11}"]
    for size in sorted({r["size"] for r in rows}, reverse=True):
        sel = [r for r in rows if r["size"] == size]
        err = np.concatenate([np.r_[r["err_alpha_urad"], r["err_beta_urad"]] for r in sel])
        sig = np.concatenate([np.r_[r["sigma_alpha_urad"], r["sigma_beta_urad"]] for r in sel])
        ratios = [
            np.median(np.r_[r["sigma_alpha_urad"], r["sigma_beta_urad"]])
            / np.sqrt(np.mean(np.r_[r["err_alpha_urad"], r["err_beta_urad"]] ** 2))
            for r in sel
        ]
        cover = np.mean(np.abs(err) <= 2 * sig)
        lines.append(
            f"{size:>4} {len(sel):>5} {100 * cover:7.1f}% {np.median(ratios):10.2f} {max(ratios):11.2f}"
        )
    return "\n".join(lines)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[14, 6])
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    p.add_argument("--profiles", nargs="+", default=["paper", "random", "zero"])
    p.add_argument("--ground", nargs="+", choices=("flat", "terrain"), default=["flat", "terrain"])
    p.add_argument("--passes", nargs="+", choices=(*PASSES, *EXTRA_PASSES), default=["day", "night"])
    p.add_argument("--mismatch", nargs="+", choices=MISMATCHES, default=["none"])
    p.add_argument("--cost", choices=[c.value for c in Cost], default=DEFAULT_COST.value)
    p.add_argument(
        "--footprints", nargs="+", choices=tuple(footprint.SHAPES), default=["top-hat"],
        help="the CrIS spatial response of the truth (monitor.instrument.footprint)",
    )  # fmt: skip
    p.add_argument("--kernel", choices=[k.value for k in Kernel], default=DEFAULT_KERNEL.value)
    p.add_argument(
        "--clouds", nargs="+", default=["ground"],
        help="cloud-height laws of the truth (monitor.simulate.clouds): ground, lapse:G, tropical",
    )  # fmt: skip
    p.add_argument(
        "--rows-error", type=float, nargs="+", default=[0.0],
        help="FOV rows ahead minus behind turned in-track by this much in the truth, urad",
    )  # fmt: skip
    p.add_argument(
        "--edges", choices=tuple(EDGES), default="soft",
        help="how sharply the truth's clouds end (monitor.simulate.scene.EDGES)",
    )  # fmt: skip
    p.add_argument("--no-parallax", action="store_true", help="assess with AssessmentConfig(parallax=False)")
    p.add_argument("--wind", type=float, default=0.0, help="the truth's clouds move along the track, m/s")
    p.add_argument("--cloud-emissivity", type=float, default=1.0, help="the truth's clouds' emissivity")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--keep", help="directory to keep the cases and results in")
    p.add_argument("--rows", help="append one JSON line per case here (errors and sigmas per FOR)")
    p.add_argument("--from-rows", help="only print the tables of the cases in this JSON-lines file")
    args = p.parse_args()
    if args.from_rows:
        rows = [json.loads(line) for line in Path(args.from_rows).read_text().splitlines() if line.strip()]
        for row in rows:
            print(verdict(row)[1])
        print(calibration(rows))
        return 0
    root = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="crisgeo-acceptance-"))
    print(
        f"{'footprint':<14} {'kernel':<9} "
        f"{'mismatch':<17} {'cost':<10} {'profile':<7} {'ground':<8} {'pass':<9} {'seed':>4} {'gran':>4} "
        f"{'rms_a':>6} {'max_a':>6} {'rms_b':>6} {'max_b':>6} {'flagged':>7} {'assess_s':>8}  verdict",
        flush=True,
    )
    rows, failures = [], 0
    done = {}
    if args.rows and Path(args.rows).exists():  # resume: cases already in the rows file are not run again
        for line in Path(args.rows).read_text().splitlines():
            if line.strip():
                r = json.loads(line)
                done[_key(r)] = r
    for case in itertools.product(
        args.sizes, args.ground, args.passes, args.profiles, args.seeds, args.mismatch, args.footprints,
        args.clouds, args.rows_error,
    ):  # fmt: skip
        size, ground, pass_name, profile, seed, mismatch, shape, clouds, rows_urad = case
        key = (
            size,
            ground,
            pass_name,
            profile,
            seed,
            mismatch,
            args.cost,
            shape,
            args.kernel,
            clouds,
            rows_urad,
            args.edges,
            not args.no_parallax,
            args.wind,
            args.cloud_emissivity,
        )
        row = done.get(key)
        if row is None:
            row = run_case(
                root, size, profile, ground, pass_name, seed, args.workers, args.keep, mismatch, args.cost,
                shape, args.kernel, clouds, rows_urad, args.edges, not args.no_parallax, args.wind,
                args.cloud_emissivity,
            )  # fmt: skip
            if args.rows:
                with open(args.rows, "a") as fh:
                    fh.write(json.dumps(row) + "\n")
        rows.append(row)
        ok, line = verdict(row)
        failures += not ok
        print(line, flush=True)
    print(calibration(rows))
    print(f"{failures} case(s) out of bounds")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
