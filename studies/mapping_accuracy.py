"""How well the mapping reads a per-band VIIRS calibration difference, and how close CrIS and VIIRS come
on a day's every FOV, on days built differently.

For each kind of day (profile, footprint, terrain, clouds with height), the same day is simulated twice,
with all four VIIRS bands: once without and once with a calibration difference injected into each band's
VIIRS BT (``--viirs-band-bias-k``). Both are mapped with the default ``crisgeo map`` (operational
geolocation, nominal response). Per band, on the FOVs uniform in VIIRS (pixels' BT spread below
``UNIFORM_K``; M13 only on scenes warmer than 260 K): the median of CrIS minus VIIRS on the day without
(``zero_median_k``), the median and rms scatter of its change between the two days, FOV by FOV
(``shift_median_k``, ``shift_scatter_k``, against the injected ``-bias``), and the rms scatter of the
biased day's CrIS minus VIIRS about its median (``scatter_k``). With ``--assess``, the day
without is also assessed (``crisgeo assess``) and mapped on its assessed geolocation and fitted response:
the rms of CrIS minus VIIRS over every FOV about the uniform FOVs' median, assessed and operational.

    .venv/bin/python -m studies.mapping_accuracy --out DIR [--granules 2] [--kinds ...] [--assess]
        [--rows studies/rows/mapping_accuracy_DATE.jsonl]
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.assess import assess_paths
from monitor.config.assessment import AssessmentConfig
from monitor.core.bands import BANDS
from monitor.instrument.footprint import shape
from monitor.matchup import Matchup, map_granules
from monitor.simulate.case import simulate_case

UNIFORM_K = 0.5
BIAS_K = {"I5": 0.1, "M13": -0.2, "M15": 0.15, "M16": -0.1}
KINDS: dict[str, dict[str, Any]] = {  # name -> the simulator's parameters; the first the default day
    "paper-flat": {},
    "random-flat": {"profile": "random", "seed": 11},
    "super-gaussian": {"cris_response": "super-gaussian", "seed": 12},
    "terrain": {"terrain": True, "seed": 13},
    "clouds-lapse5.2": {"cloud_heights": "lapse:5.2", "seed": 14},
    "night-sharp": {"orbit_pass": "night", "cloud_edges": "sharp", "seed": 15},
}


def _difference(m: Matchup, band: str) -> tuple[np.ndarray, np.ndarray]:
    """CrIS minus VIIRS of every FOV in *band*, and where the FOV is uniform (and warm enough)."""
    b = m.bands.index(band)
    d = m.values["cris_bt_k"][b] - m.values["viirs_bt_k"][b]
    keep = (m.values["viirs_bt_std_k"][b] < UNIFORM_K) & np.isfinite(d)
    low = BANDS[band].min_scene_k
    if low is not None:
        keep &= m.values["viirs_bt_k"][b] > low
    return d, keep


def run_kind(name: str, out: Path, granules: int, assess: bool, rows: str | None) -> None:
    """Simulate one kind of day with and without the differences, map both, emit a row per band."""
    params = dict(KINDS[name])
    response = params.pop("cris_response", None)
    if response is not None:
        params["cris_response"] = shape(str(response))
    days = {}
    for tag, bias in (("zero", {}), ("biased", BIAS_K)):
        where = out / f"{name}-{tag}"
        if not (where / "truth.json").exists():
            simulate_case(
                where, granules=granules, viirs_bands=tuple(BANDS), viirs_band_bias_k=bias, **params
            )
        days[tag] = where
    zero, _ = map_granules([days["zero"]])
    biased, _ = map_granules([days["biased"]])
    assessed = None
    if assess:
        result = assess_paths([days["zero"]], AssessmentConfig())
        assessed, _ = map_granules([days["zero"]], offsets=result)
    for band in BANDS:
        d0, keep0 = _difference(zero, band)
        d1, keep1 = _difference(biased, band)
        both = keep0 & keep1
        shift = d1[both] - d0[both]
        row = {
            "kind": name,
            "band": band,
            "granules": granules,
            "uniform_fovs": int(both.sum()),
            "zero_median_k": round(float(np.median(d0[keep0])), 4),
            "injected_k": -BIAS_K[band],
            "shift_median_k": round(float(np.median(shift)), 4),
            "shift_scatter_k": round(float(np.sqrt(np.mean((shift - np.median(shift)) ** 2))), 4),
            # the biased day's own CrIS minus VIIRS on its uniform FOVs, about its median: noise and scene
            "scatter_k": round(float(np.sqrt(np.mean((d1[keep1] - np.median(d1[keep1])) ** 2))), 4),
        }
        for label, m in (("operational", zero), ("assessed", assessed)):
            if m is None:
                continue
            d, keep = _difference(m, band)
            every = np.isfinite(d)
            if BANDS[band].min_scene_k is not None:
                b = m.bands.index(band)
                every &= m.values["viirs_bt_k"][b] > BANDS[band].min_scene_k
            row[f"rms_all_fovs_{label}_k"] = round(
                float(np.sqrt(np.mean((d[every] - np.median(d[keep])) ** 2))), 4
            )
        row["commit"] = commit()
        emit(row, rows)


def main() -> None:
    """Run the kinds asked for; one JSON row per kind and band."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="where the simulated days are kept (reused when there)")
    p.add_argument("--granules", type=int, default=2)
    p.add_argument("--kinds", nargs="+", default=list(KINDS), choices=list(KINDS))
    p.add_argument("--assess", action="store_true", help="also map the day on its assessed geolocation")
    p.add_argument("--rows", help="append the rows to this file")
    args = p.parse_args()
    for name in args.kinds:
        run_kind(name, Path(args.out), args.granules, args.assess, args.rows)


if __name__ == "__main__":
    main()
