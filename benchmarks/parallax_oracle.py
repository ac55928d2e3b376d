"""What a perfect parallax correction would give: the clouds-with-height case assessed with each VIIRS pixel
standing at the true height of what it sees, against the day's learnt heights.

The learnt correction stands a pixel kappa times how much colder it is than its clear-sky neighbourhood
above its GEO point (``monitor/collocation/lift.py``) and renders what each CrIS FOV row sees of that
(``monitor/collocation/render.py``). This bench asks how much better heights would give, and what no height
removes. It simulates the case once, recording for every VIIRS pixel row the height above the ground of
the first cloud or terrain its ray meets (the simulator's own intersection), then assesses it twice with
the same default configuration: as shipped, and with the probe collocation rendered from the true heights
and the day's fraction held at 1 (the oracle; the walls keep the probe's law). Flat ground only (the true
height is then the hit's). Rows of 2026-11-26 measured the point lift, which the rendering replaced.

    .venv/bin/python -m benchmarks.parallax_oracle [--clouds lapse:6.5] [--seed 11] [--granules 6]

Prints RMS and worst FOR per direction for both, with the bounds (6 granules: RMS <= 12, worst <= 30 urad).
A test-only hook: the simulator and the collocation are patched in this process; nothing ships.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol, cast

import numpy as np
from numpy.typing import ArrayLike

from benchmarks.provenance import commit, emit
from monitor.assessment.assess import assess_paths
from monitor.collocation import render
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import VIIRS_COLUMNS
from monitor.core.result import AssessmentResult
from monitor.estimation import parallax as day_parallax
from monitor.simulate import case as sim
from monitor.simulate.case import simulate_case

TRUTH: dict[tuple[float, float], np.ndarray] = {}  # row key (:func:`_key`) -> lift (m) of each pixel


def _key(lat_deg: np.ndarray, lon_deg: np.ndarray) -> list[tuple[float, float]]:
    """Row keys of (rows, cols) degrees: the middle column's position to 1e-4 deg (~10 m; GEO's float32
    degrees come back through radians) identifies a pixel row."""
    mid = lat_deg.shape[1] // 2
    lat = np.round(np.asarray(lat_deg[:, mid], np.float64), 4)
    lon = np.round(np.asarray(lon_deg[:, mid], np.float64), 4)
    return list(zip(lat.tolist(), lon.tolist(), strict=True))


def _recording(
    self: sim.Simulator, origin: np.ndarray, los: np.ndarray, unix_s: ArrayLike, ground: sim.Point
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The simulator's ``met`` (its body, for clouds with height), also recording per pixel row the
    geodetic height of what the rays meet: on flat ground, the lift a perfect correction would apply."""
    _, s_lat, s_lon, s_h = self.scene.intersect(origin, los, unix_s=unix_s)
    if los.shape[-2] != VIIRS_COLUMNS:  # CrIS's rays: not recorded
        return s_lat, s_lon, s_h
    lat, lon, _ = ground
    rows_lat = np.degrees(lat).astype(np.float32).reshape(-1, VIIRS_COLUMNS)
    rows_lon = np.degrees(lon).astype(np.float32).reshape(-1, VIIRS_COLUMNS)
    lift = np.nan_to_num(s_h, nan=0.0).reshape(-1, VIIRS_COLUMNS)
    for key, row in zip(_key(rows_lat, rows_lon), lift, strict=True):
        TRUTH[key] = row.astype(np.float32)
    return s_lat, s_lon, s_h


class _Counted(Protocol):
    """The true heights' wrapper, counting the pixel rows it found a truth for."""

    rows: int
    total: int

    def __call__(self, *args: np.ndarray | float | slice) -> np.ndarray: ...


def _true_heights(rendered: Callable[..., np.ndarray]) -> _Counted:
    """``monitor.collocation.render.rendered_bt`` with each pixel standing at the recorded truth (0 where
    none) instead of the height its BT implies; the walls keep the day's law."""

    def wrapped(
        lat_rad: np.ndarray,
        lon_rad: np.ndarray,
        height_m: np.ndarray,
        bt_k: np.ndarray,
        good: np.ndarray,
        sat_m: np.ndarray,
        velocity_m_s: np.ndarray,
        cris_alpha_rad: np.ndarray,
        m_per_k: float,
        *where: slice,
    ) -> np.ndarray:
        lat = np.degrees(np.asarray(lat_rad, np.float64)).astype(np.float32)
        lon = np.degrees(np.asarray(lon_rad, np.float64)).astype(np.float32)
        truth = np.zeros(np.shape(bt_k), np.float32)
        found = 0
        for i, key in enumerate(_key(lat, lon)):
            row = TRUTH.get(key)
            if row is not None:
                truth[i] = row
                found += 1
        # only where GEO has a position (the deleted bow-tie pixels and fill rows have none)
        truth = np.where(np.isfinite(lat) & np.isfinite(lon) & (np.abs(lat) <= 90.0), truth, 0.0)
        counted.rows += found
        counted.total += len(truth)
        own = render.height_above_m
        render.height_above_m = lambda *_: truth  # the recorded heights
        try:
            return rendered(
                lat_rad, lon_rad, height_m, bt_k, good, sat_m, velocity_m_s, cris_alpha_rad, m_per_k, *where
            )
        finally:
            render.height_above_m = own

    counted = cast(_Counted, wrapped)
    counted.rows = counted.total = 0
    return counted


def _scores(result: AssessmentResult, truth: dict) -> dict:
    ta = np.array([f["d_alpha_urad"] for f in truth["fors"]])
    tb = np.array([f["d_beta_urad"] for f in truth["fors"]])
    ea = np.array([f.d_alpha_urad for f in result.fors]) - ta
    eb = np.array([f.d_beta_urad for f in result.fors]) - tb
    sa = np.array([f.sigma_alpha_urad for f in result.fors])
    sb = np.array([f.sigma_beta_urad for f in result.fors])
    return {
        "rms_urad": [float(np.sqrt(np.nanmean(ea**2))), float(np.sqrt(np.nanmean(eb**2)))],
        "worst_urad": [float(np.nanmax(np.abs(ea))), float(np.nanmax(np.abs(eb)))],
        "within_2_sigma": float(np.mean(np.r_[np.abs(ea) <= 2 * sa, np.abs(eb) <= 2 * sb])),
        "err_alpha_urad": ea.tolist(),
        "err_beta_urad": eb.tolist(),
    }


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--clouds", default="lapse:6.5")
    p.add_argument("--seed", type=int, default=11)
    p.add_argument("--granules", type=int, default=6)
    p.add_argument("--rows", help="append the JSON line here")
    args = p.parse_args()
    root = Path(tempfile.mkdtemp(prefix="crisgeo-oracle-"))
    sim.Simulator.met = _recording  # type: ignore[method-assign]  # the oracle's recording seam
    t0 = time.perf_counter()
    truth = simulate_case(
        root, granules=args.granules, profile="paper", seed=args.seed, cloud_heights=args.clouds,
        cris_response=None,
    )  # fmt: skip
    print(
        f"simulated in {time.perf_counter() - t0:.0f} s; {len(TRUTH)} VIIRS pixel rows recorded", flush=True
    )
    cfg = AssessmentConfig()
    shipped = _scores(assess_paths([root], cfg), truth)
    true_lift = _true_heights(render.rendered_bt)
    render.rendered_bt = true_lift  # type: ignore[assignment]  # the same call, counted
    day_parallax.day_lift = lambda s0, s1, cost, probe_m_per_k: (1.0, float("nan"))
    oracle = _scores(assess_paths([root], cfg), truth)
    print(f"oracle rows matched {true_lift.rows}/{true_lift.total}")
    for name, s in (("shipped", shipped), ("true heights", oracle)):
        print(
            f"{name:<13} RMS {s['rms_urad'][0]:5.1f} / {s['rms_urad'][1]:5.1f} urad, worst "
            f"{s['worst_urad'][0]:5.1f} / {s['worst_urad'][1]:5.1f}, "
            f"within 2 sigma {100 * s['within_2_sigma']:.0f} %"
        )
    emit(
        {
            "commit": commit(),
            "clouds": args.clouds,
            "seed": args.seed,
            "granules": args.granules,
            "shipped": shipped,
            "oracle": oracle,
        },
        args.rows,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
