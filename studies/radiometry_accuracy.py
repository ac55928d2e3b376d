"""How well the day's CrIS minus VIIRS per band and FOR (``monitor.matchup.radiometry``, the default
configuration's uniformity test) reads a per-band calibration difference, and whether its sigmas are honest,
on days built differently.

For each kind of day of ``studies.mapping_accuracy`` (profile, footprint, terrain, clouds with height, a
night pass with sharp edges), the same day is simulated twice with all four bands, without and with a VIIRS
difference of both signs in every band (``INJECTED_K``, 0.05-0.3 K). Both are assessed with the default
configuration and mapped on their own assessed geolocation and fitted response, as the daily run does. Per
band: the median over FORs of the difference between the two days (against minus the injection: CrIS minus
VIIRS reads minus what VIIRS gains), the share of FORs whose difference lies within 2 sigma of the truth
(the injection plus the day without's median, the simulator's own spectral residual), the median sigma and
the FORs with a value.

    .venv/bin/python -m studies.radiometry_accuracy --out DIR [--granules 3] [--kinds ...]
        [--rows studies/rows/radiometry_accuracy_DATE.jsonl]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.assess import assess_paths
from monitor.assessment.daymap import with_bands
from monitor.config.assessment import AssessmentConfig
from monitor.core.bands import BANDS
from monitor.core.result import AssessmentResult
from monitor.instrument.footprint import shape
from monitor.matchup import map_granules
from monitor.simulate.case import simulate_case
from studies.mapping_accuracy import KINDS

INJECTED_K = {"I5": 0.3, "M13": -0.05, "M15": -0.12, "M16": 0.08}  # added to VIIRS's BT
ALL = tuple(BANDS)


def _day(out: Path, kind: dict, granules: int, bias: dict[str, float]) -> AssessmentResult:
    """Simulate, assess and compare one day in every band, with the default configuration."""
    params = dict(kind)
    response = params.pop("cris_response", None)
    if response is not None:
        params["cris_response"] = shape(str(response))
    simulate_case(out, granules=granules, viirs_bands=ALL, viirs_band_bias_k=bias, **params)
    cfg = AssessmentConfig(bands=list(ALL))
    result = assess_paths([out], cfg, workers=2)
    matchup, _ = map_granules([out], ALL, offsets=result)
    return with_bands(result, matchup, cfg)


def _column(result: AssessmentResult, field: str, band: str) -> np.ndarray:
    """A per-band field of every FOR."""
    return np.array([getattr(f, f"{field}_{band}") for f in result.fors])


def run_kind(name: str, out: Path, granules: int, rows: str | None) -> None:
    """One kind of day without and with the differences; a row per band."""
    plain = _day(out / f"{name}-plain", KINDS[name], granules, {})
    biased = _day(out / f"{name}-biased", KINDS[name], granules, INJECTED_K)
    for band in ALL:
        p, b = _column(plain, "cris_minus_viirs_k", band), _column(biased, "cris_minus_viirs_k", band)
        s = _column(biased, "sigma_cris_minus_viirs_k", band)
        truth = float(np.nanmedian(p)) - INJECTED_K[band]
        ok = np.isfinite(b) & np.isfinite(s)
        emit(
            {
                "commit": commit(),
                "kind": name,
                "granules": granules,
                "band": band,
                "injected_k": -INJECTED_K[band],
                "read_median_k": float(np.nanmedian(b - p)),
                "fors": int(ok.sum()),
                "within_2_sigma": float(np.mean(np.abs(b[ok] - truth) <= 2 * s[ok])) if ok.any() else None,
                "median_sigma_k": float(np.median(s[ok])) if ok.any() else None,
            },
            rows,
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder for the simulated days")
    ap.add_argument("--granules", type=int, default=3)
    ap.add_argument("--kinds", nargs="*", default=list(KINDS), choices=list(KINDS))
    ap.add_argument("--rows", help="append the JSON lines here")
    args = ap.parse_args()
    for name in args.kinds:
        run_kind(name, Path(args.out), args.granules, args.rows)


if __name__ == "__main__":
    main()
