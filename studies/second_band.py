"""How well the offsets read in M15 (``monitor.estimation.band_pair``) agree with the truth and with I5's, on
the simulated acceptance days: flat and cloudy (clouds with height at 5.2 K/km), the paper's top-hat footprint
and a smooth one (super-Gaussian), each day with its own seed.

Each day is simulated in I5 and M15, assessed with the default configuration plus M15 in ``bands`` (I5's
offsets, then the same granules in M15, as the daily run does), and compared with the simulator's truth. Per
band over the FORs without a reliability flag, both directions pooled: the RMS error, the share within 2 sigma
of the truth (cover2), the median sigma; and of the difference (the truth's is zero), the share within 3 of
its paired sigmas and the FORs flagged ``bands_differ`` (each one false).

    .venv/bin/python -m studies.second_band --out DIR [--granules 6] [--kinds ...] [--seeds ...]
        [--rows studies/rows/second_band_DATE.jsonl]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.assess import assess_plan, in_second_band
from monitor.config.assessment import AssessmentConfig
from monitor.core.result import FLAG_BANDS_DIFFER, AssessmentResult
from monitor.instrument.footprint import shape
from monitor.sdr.pairing import plan
from monitor.simulate.case import simulate_case

BANDS = ("I5", "M15")
KINDS: dict[str, dict[str, Any]] = {  # name -> the simulator's parameters
    "flat-top-hat": {},
    "flat-smooth": {"cris_response": "super-gaussian"},
    "cloudy-top-hat": {"cloud_heights": "lapse:5.2"},
    "cloudy-smooth": {"cloud_heights": "lapse:5.2", "cris_response": "super-gaussian"},
}


def _errors(result: AssessmentResult, truth: dict, suffix: str) -> tuple[np.ndarray, np.ndarray]:
    """The errors and sigmas (urad) of a band's offsets over the reliable FORs, both directions pooled."""
    keep = [f for f in result.fors if f.reliable]
    by_for = {f["for"]: f for f in truth["fors"]}
    err, sig = [], []
    for f in keep:
        t = by_for[f.for_index]
        for axis in ("alpha", "beta"):
            err.append(getattr(f, f"d_{axis}_urad{suffix}") - t[f"d_{axis}_urad"])
            sig.append(getattr(f, f"sigma_{axis}_urad{suffix}"))
    return np.array(err), np.array(sig)


def _summary(err: np.ndarray, sig: np.ndarray) -> dict[str, float]:
    ok = np.isfinite(err) & np.isfinite(sig)
    return {
        "rms_urad": float(np.sqrt(np.mean(err[ok] ** 2))),
        "cover2": float(np.mean(np.abs(err[ok]) <= 2 * sig[ok])),
        "median_sigma_urad": float(np.median(sig[ok])),
        "n": int(ok.sum()),
    }


def run_day(name: str, seed: int, out: Path, granules: int, rows: str | None) -> None:
    """Simulate, assess in both bands and compare one day; one row."""
    params = dict(KINDS[name])
    response = params.pop("cris_response", None)
    if response is not None:
        params["cris_response"] = shape(str(response))
    where = out / f"{name}-{seed}"
    if not (where / "truth.json").exists():
        simulate_case(where, granules=granules, seed=seed, viirs_bands=BANDS, **params)
    truth = json.loads((where / "truth.json").read_text())
    cfg = AssessmentConfig(bands=list(BANDS))
    case = plan([where], bands=BANDS)
    result = assess_plan(case, cfg, workers=cfg.workers)
    both = in_second_band(case, result, cfg)
    i5, m15 = _summary(*_errors(both, truth, "")), _summary(*_errors(both, truth, "_M15"))
    pairs = [f for f in both.fors if f.reliable and np.isfinite(f.d_alpha_urad_M15)]
    d = np.array([getattr(f, f"m15_minus_i5_{a}_urad") for f in pairs for a in ("alpha", "beta")])
    s = np.array([getattr(f, f"sigma_m15_minus_i5_{a}_urad") for f in pairs for a in ("alpha", "beta")])
    ok = np.isfinite(d) & np.isfinite(s)
    emit(
        {
            "commit": commit(),
            "kind": name,
            "seed": seed,
            "granules": granules,
            "i5": i5,
            "m15": m15,
            "rms_ratio": m15["rms_urad"] / i5["rms_urad"],
            "median_sigma_ratio": m15["median_sigma_urad"] / i5["median_sigma_urad"],
            "difference_within_3_sigma": float(np.mean(np.abs(d[ok]) <= 3 * s[ok])) if ok.any() else None,
            "difference_rms_urad": float(np.sqrt(np.mean(d[np.isfinite(d)] ** 2))),
            "median_paired_sigma_urad": float(np.median(s[ok])) if ok.any() else None,
            "bands_differ": sum(FLAG_BANDS_DIFFER in f.flags for f in both.fors),
        },
        rows,
    )


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="where the simulated days are kept")
    p.add_argument("--granules", type=int, default=6)
    p.add_argument("--kinds", nargs="+", choices=tuple(KINDS), default=list(KINDS))
    p.add_argument("--seeds", type=int, nargs="+", default=[41])
    p.add_argument("--rows", help="append one JSON line per day here")
    args = p.parse_args()
    for seed in args.seeds:
        for name in args.kinds:
            run_day(name, seed + list(KINDS).index(name), Path(args.out), args.granules, args.rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
