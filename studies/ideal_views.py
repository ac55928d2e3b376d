"""What the collocation would give if VIIRS saw along CrIS's views: each simulated case assessed with the
rendering replaced by the simulator's own views, the bound that no renderer of VIIRS's pixels can pass.

The assessment renders, for each in-track SBF angle of :data:`monitor.collocation.render.VIEW_ALPHA_RAD`,
the BT a CrIS ray at that angle meets on its way to each VIIRS GEO point (:func:`render.rendered_bt`,
from the pixels' BT, a height learnt from the day and walls at the height law). Here that BT comes from
the simulator itself instead: the spacecraft at the time it sees the GEO point at that angle (the secant
search of :mod:`studies.render_truth`), its ray marched through the case's scene, the band BT of what
it meets plus VIIRS's noise. Everything else is the service's: the same collocation, footprint kernel,
cost, minimum and jackknife, with the day's fraction held at 1 (``parallax=False`` on the rendered
samples, as ``studies.lift_decision --at-law`` does). What this leaves is what the view angles
themselves leave (each FOV's one in-track angle, views 20 mrad apart blended linearly), the footprint,
the noise and the day's scenes: the part of the error that better heights, walls or reference cannot
remove.

    .venv/bin/python -m studies.ideal_views CASE_DIR... [--workers 2] [--sweep] [--no-ideal] [--rows FILE]

A case directory is one ``crisgeo simulate`` wrote, with truth.json; its scene is simulated again from
the truth's parameters (the seed gives the same scene). One JSON row per case: the errors as the service
assesses it ("default"), with ``parallax=False`` ("no_parallax", the same collocation at no lift) and
from the ideal views ("ideal"), with the bounds' fields of
``studies.lift_decision``; "centre_view_k" is the median and 99th percentile of |ideal centre view -
VIIRS's own BT| over the rendered pixels (a check that the scene is the case's: VIIRS's own view is within
7 mrad of the centre's, so most pixels differ by the noise alone). With ``--sweep`` the row also holds the
errors as the service assesses the case when each ray takes the BT of the pixel its column's sweep meets,
not of its own place across the track ("sweep": :func:`monitor.collocation.render.swept_bt`); with
``--no-ideal`` it holds the service's assessments alone (no "ideal", no tracing).
"""

from __future__ import annotations

import argparse
import datetime as dt
import inspect
import json
import time
from pathlib import Path

import numpy as np

from benchmarks.provenance import emit
from monitor.assessment.estimates import cost_and_offsets, paired
from monitor.collocation import render
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import VIIRS_DETECTORS
from monitor.geometry import frames, wgs84
from monitor.simulate.case import SimulationSpec, Simulator
from studies.collocated import collocated
from studies.lift_decision import case_fields, scores
from studies.render_truth import band_bt, view_time

SCENE_FIELDS = (
    "satellite", "granules", "seed", "profile", "orbit_pass", "pass_lon_deg", "terrain", "cloud_heights",
    "cloud_edges", "fov_rows_alpha_urad", "wind_in_track_m_s", "cloud_emissivity",
)  # fmt: skip
RENDERED_BT = inspect.signature(render.rendered_bt)  # the arguments the stand-in takes
CHUNK = 200_000  # pixels traced at once (the scene's march holds a few arrays of this many rays)


def simulator_of(truth: dict) -> Simulator:
    """The simulator that wrote the case of *truth* (truth.json): its scene and orbit from the same
    parameters and seed."""
    spec = SimulationSpec(
        **{k: truth[k] for k in SCENE_FIELDS if k in truth}, start=dt.datetime.fromisoformat(truth["start"])
    )
    return Simulator(spec)


class IdealViews:
    """A stand-in for :func:`monitor.collocation.render.rendered_bt` with its arguments: the simulator's own
    view of each GEO point at each in-track angle (module docstring); *m_per_k* is not used."""

    def __init__(self, sim: Simulator) -> None:
        self.sim = sim
        self.rng = np.random.default_rng(sim.spec.seed + 1)
        span = sim.viirs_granule_starts()
        self.t_grid = np.arange(span[0] - 120.0, span[-1] + 300.0, 0.25)
        self.r_grid, _, _ = sim.state(self.t_grid)
        self.pixels = 0
        self.trace_s = 0.0
        self.centre_diff_k: list[np.ndarray] = []

    def __call__(self, *args: object, **kwargs: object) -> np.ndarray:
        a = RENDERED_BT.bind(*args, **kwargs)
        a.apply_defaults()
        lat_rad, lon_rad, height_m, bt_k, good, sat_m = (
            np.asarray(a.arguments[k]) for k in ("lat_rad", "lon_rad", "height_m", "bt_k", "good", "sat_m")
        )
        cris_alpha_rad = np.asarray(a.arguments["cris_alpha_rad"])
        scans, columns = a.arguments["scans"], a.arguments["columns"]
        t0 = time.perf_counter()
        rows, cols = np.shape(bt_k)
        out = np.full((len(cris_alpha_rad), rows, cols), np.nan, np.float32)
        first, stop, _ = scans.indices(rows // VIIRS_DETECTORS)
        r = slice(first * VIIRS_DETECTORS, stop * VIIRS_DETECTORS)
        usable = np.zeros((rows, cols), bool)
        usable[r, columns] = np.asarray(good, bool)[r, columns] & np.isfinite(bt_k[r, columns])
        iy, ix = np.nonzero(usable)
        # each pixel's scan time from its scan's spacecraft position: the search's first guess
        scan_t = self.t_grid[
            np.argmin(np.linalg.norm(self.r_grid[None] - np.asarray(sat_m)[:, None], axis=-1), axis=1)
        ]
        t_guess = scan_t[iy // VIIRS_DETECTORS]
        p = wgs84.geodetic_to_ecef(lat_rad[iy, ix], lon_rad[iy, ix], height_m[iy, ix])
        noise = self.sim.spec.viirs_noise_k
        for j, alpha in enumerate(cris_alpha_rad):
            seen = np.empty(len(iy), np.float32)
            for c0 in range(0, len(iy), CHUNK):
                c = slice(c0, c0 + CHUNK)
                t_view = view_time(self.sim, p[c], t_guess[c], float(alpha))
                r_view, _, _ = self.sim.state(t_view)
                scene = self.sim.scene
                _, v_lat, v_lon, _ = scene.intersect(r_view, frames.unit(p[c] - r_view), unix_s=t_view)
                temp = scene.temperature_k(v_lat, v_lon, scene.height_m(v_lat, v_lon), t_view)
                seen[c] = band_bt(self.sim, temp) + self.rng.normal(0.0, noise, len(temp))
            out[j, iy, ix] = seen
            if alpha == 0.0:
                self.centre_diff_k.append(np.abs(seen - bt_k[iy, ix]))
        self.pixels += len(iy)
        self.trace_s += time.perf_counter() - t0
        return out


def measure(case: Path, workers: int, sweep: bool = False, ideal_views: bool = True) -> dict:
    """The row of one case (module docstring); without *ideal_views*, the service's assessments alone."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig(workers=workers)
    plain = cfg.model_copy(update={"parallax": False})
    samples = collocated(case, cfg, workers, PROBE_M_PER_K)
    default = cost_and_offsets(samples, cfg, satellite=truth["satellite"])
    row = {**case_fields(case, truth), "granules": truth["granules"], "default": scores(default, truth)}
    row["no_parallax"] = scores(
        cost_and_offsets(paired(samples)[0], plain, satellite=truth["satellite"]), truth
    )
    if ideal_views:
        ideal = IdealViews(simulator_of(truth))
        again = collocated(case, cfg, workers, PROBE_M_PER_K, renderer=ideal)  # the truth for the rendering
        at = cost_and_offsets(paired(again)[1], plain, satellite=truth["satellite"])
        diff = np.concatenate(ideal.centre_diff_k) if ideal.centre_diff_k else np.full(1, np.nan)
        row["ideal"] = scores(at, truth)
    if sweep:
        renderer = render.swept_bt
        both = collocated(case, cfg, workers, PROBE_M_PER_K, renderer=renderer)
        row["sweep"] = scores(cost_and_offsets(both, cfg, satellite=truth["satellite"]), truth)
    if ideal_views:
        centre = (np.nanmedian(diff), np.nanpercentile(diff, 99))
        row["centre_view_k"] = [round(float(v), 2) for v in centre]
        row["pixels_traced"], row["trace_s"] = ideal.pixels, round(ideal.trace_s)
    return row


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", type=Path)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--sweep", action="store_true", help="also assess with the sweep alone (render.swept_bt)")
    p.add_argument("--no-ideal", action="store_true", help="the service's assessments alone, no ideal views")
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    for case in args.cases:
        emit(measure(case, args.workers, args.sweep, not args.no_ideal), args.rows)


if __name__ == "__main__":
    main()
