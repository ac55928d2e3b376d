"""The renderer against the simulator's own ray tracing: what a CrIS FOV row's ray to each VIIRS GEO point
meets, rendered from VIIRS's pixels at their true heights, beside the truth.

The collocation's renderer (:mod:`monitor.collocation.render`) sweeps each CrIS ray down each VIIRS
column's slanted plane, the pixels standing at the height of what VIIRS met. Here it is given the true
heights (the simulator's own intersection of each VIIRS ray), so every difference from the truth is the
renderer's.
The truth at a GEO point P for the in-track SBF angle alpha: the spacecraft at the time t' when P lies at
alpha in its SBF (a secant search on the simulator's own orbit and attitude), its ray to P marched through
the simulator's scene, and the band BT of what it meets. Beside it, "geo" is VIIRS's own BT at P (no
correction: the parallax left).

For each angle it prints the RMS of the per-pixel error (K), the RMS over 400 discs of 7 km radius (a CrIS
FOV's size) of the disc-mean error (K: what the cost sees), and the share of pixels more than 5 K off by
detector (0-7 and 24-31: a scan's edges; 8-23 its middle), and the renderer's wall time (s) for the three
views. One JSON row. Rows before 2026-11-28 11:30 also hold the two-dimensional column march the renderer
was then ("render") and the sweep measured here before it replaced that ("sweep", "sweep_linear"; nearest
and linear tops).

For each angle it also prints the renderer's cross-track shift, in VIIRS columns, in each sixth of the
scan ("cross_track_columns"): the renderer is given each pixel's hit point (ECEF, where VIIRS's ray met
the scene) as its field, so what it renders at a GEO point is where it takes that point's value from;
that minus the truth's hit point, along the scan's direction at the GEO point (its next column), over the
rays whose truth meets a cloud above 1 km: median, 16th and 84th percentiles, and the count. A top's BT
taken from a pixel a column aside reads +-1 here.

With ``--reaches 40,100`` the views are also rendered from the heights the assessment would give the
pixels (:func:`monitor.collocation.lift.height_above_m` at the law, the clear-sky reference the warmest
3 x 3 mean within each reach), the fields "reference_40px" ...; the row's "heights" holds their bias and
RMS (m) against the true heights over the tops above 6 km and over the pixels that see the ground
(docs/science.md, "The clear-sky reference").

With ``--across`` the renderer takes each ray's BT at its own position across the track
(:func:`monitor.collocation.views.view_tangents_across`); the row says which ("across").

    .venv/bin/python -m studies.render_truth [--clouds lapse:6.5] [--edges sharp] [--seed 11]
        [--scans 8] [--reaches 40,100] [--across] [--rows FILE]

The scene is VIIRS's first granule of a one-granule case, from its 11th scan on; no noise. The walls and
the reference's heights take the case's law in band BT (:func:`monitor.simulate.case.law_m_per_k`; rows
before 2026-11-29 took the band's slope at 270 K, 189.2 m/K at 6.5 K/km, and 6.5 K/km's for the tropical
profile).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial import cKDTree

from benchmarks.provenance import commit, emit
from monitor.collocation import lift, render, views
from monitor.core.constants import VIIRS_COLUMNS, VIIRS_DETECTORS
from monitor.geometry import frames, wgs84
from monitor.simulate import scan_geometry as ins
from monitor.simulate.case import T_BINS_K, SimulationSpec, Simulator, law_m_per_k

ALPHA_RAD = np.array([19.1e-3, 0.0, -19.1e-3])  # the rows ahead, the centre, the rows behind
DISC_M = 7000.0
EDGE_DETECTORS = np.r_[0:8, 24:32]
SIXTHS = 6  # the scan's parts the cross-track shift is stated in
CLOUD_M = 1000.0  # the truth's rays that meet something higher than this count in the shift
WALLS_AS_STRETCHES = 1e30  # m per K: a wall renders as its stretch's own field (no depth term)


def band_bt(sim: Simulator, temp_k: np.ndarray) -> np.ndarray:
    """VIIRS I5 BT (K) of emitting temperatures *temp_k* through the simulator's atmosphere."""
    return sim.band.bt_from_radiance(np.interp(temp_k, T_BINS_K, sim.band_table))


def view_time(sim: Simulator, p: np.ndarray, t: np.ndarray, alpha: float) -> np.ndarray:
    """When the spacecraft sees ECEF points *p* (N, 3) at in-track SBF angle *alpha*: a secant search from
    the VIIRS times *t*."""

    def miss(ts: np.ndarray) -> np.ndarray:
        r, _, m = sim.state(ts)
        sbf = np.einsum("nji,nj->ni", m, p - r)
        return sbf[:, 0] / sbf[:, 2] - np.tan(alpha)

    ta, fa = t, miss(t)
    tb = t + 1.0
    fb = miss(tb)
    for _ in range(5):
        step = np.divide(fb * (tb - ta), fb - fa, out=np.zeros_like(fb), where=fb != fa)
        ta, fa, tb = tb, fb, tb - step
        fb = miss(tb)
    return tb


def _height_errors(height_m: np.ndarray, true_m: np.ndarray) -> dict:
    """Bias and RMS (m) of *height_m* against the true heights, over the tops above 6 km and over the
    pixels that see the ground (true height under 100 m)."""
    out = {}
    for name, sel in (("tops_6km", true_m >= 6000.0), ("ground", true_m < 100.0)):
        e = (height_m - true_m)[sel]
        out[name] = {"bias_m": round(float(e.mean()), 0), "rms_m": round(float(np.sqrt(np.mean(e**2))), 0)}
    return out


def _shift_columns(
    x: np.ndarray,
    b: np.ndarray,
    a: np.ndarray,
    height: np.ndarray,
    good: np.ndarray,
    hit_p: np.ndarray,
    geo_p: np.ndarray,
    across: views.Across | None,
) -> np.ndarray:
    """Per view, the point the renderer takes each GEO point's value from: each pixel's hit point rendered
    as a field (NaN where it takes none).

    Parameters
    ----------
    x, b, a, height : numpy.ndarray
        :func:`views.view_tangents`'s along-track coordinate and tangents and the pixels' heights (m).
    good : numpy.ndarray
        Where a pixel is usable, shape (rows, cols).
    hit_p : numpy.ndarray
        Where VIIRS's ray of each pixel met the scene, ECEF, m, shape (rows, cols, 3).
    geo_p : numpy.ndarray
        Each pixel's GEO point, ECEF, m, shape (rows, cols, 3).
    across : views.Across or None
        Where the rays lie across the track, when the renderer takes it.

    Returns
    -------
    numpy.ndarray
        ECEF, m, shape (views, rows, cols, 3); the caller measures it against the truth's hit point
        along the scan, per view.
    """
    centre = np.nanmean(geo_p[good], axis=0)  # float32 renders: keep the field's values small
    rendered = np.stack(
        [
            render.render_height_field(
                np.where(good, x, np.nan), b, height, hit_p[..., k] - centre[k], a, WALLS_AS_STRETCHES, across
            ).astype(np.float64)
            for k in range(3)
        ],
        -1,
    )
    return rendered + centre


def measure(
    clouds: str, edges: str, seed: int, scans: int, reaches_px: tuple[int, ...] = (), across: bool = False
) -> dict:
    """The row (module docstring)."""
    sim = Simulator(SimulationSpec(granules=1, seed=seed, cloud_heights=clouds, cloud_edges=edges))
    theta, col_dt = ins.viirs_column_geometry()
    a_det = ins.viirs_detector_angles_rad()
    local = frames.unit(np.stack([np.tan(a_det), np.zeros_like(a_det), np.ones_like(a_det)], -1))
    los_sbf = np.einsum("cij,dj->dci", frames.rot_x(-theta), local)
    scan_start = float(sim.viirs_granule_starts()[0]) + (10 + np.arange(scans)) * ins.VIIRS_SCAN_S
    pixel_s = scan_start[:, None] + col_dt[None, :]
    r, _, m = sim.state(pixel_s)
    los = np.einsum("scij,dcj->sdci", m, los_sbf)
    origin = np.broadcast_to(r[:, None], los.shape)
    lat, lon, _ = sim.surface(origin, los)
    t3 = np.broadcast_to(pixel_s[:, None, :], lat.shape)
    hit_dist, hit_lat, hit_lon, hit_m = sim.scene.intersect(origin, los, unix_s=t3)
    temp = sim.scene.temperature_k(hit_lat, hit_lon, sim.scene.height_m(hit_lat, hit_lon), t3)
    shape = (scans * VIIRS_DETECTORS, VIIRS_COLUMNS)
    hit_p = (origin + hit_dist[..., None] * los).reshape(*shape, 3)
    lat, lon, hit_m, times = (np.asarray(v).reshape(shape) for v in (lat, lon, hit_m, t3))
    bt = band_bt(sim, temp).reshape(shape)
    good = ~np.tile(ins.viirs_bowtie_deleted(), (scans, 1)) & np.isfinite(lat)
    sat, vel = sim.orbit.state_ecef(scan_start + ins.VIIRS_EARTH_VIEW_S / 2)
    x, b, a, traced = views.view_tangents_across(lat, lon, np.zeros(shape), good, sat, vel, ALPHA_RAD)
    sideways = traced if across else None
    m_per_k = law_m_per_k(sim.spec.satellite, clouds)  # the law, in metres per kelvin of band BT
    if m_per_k is None:
        raise ValueError(f"clouds {clouds!r}: nothing stands above the ground to render")
    t0 = time.perf_counter()
    height = np.where(good, np.nan_to_num(hit_m), 0.0)
    rendered = render.render_height_field(np.where(good, x, np.nan), b, height, bt, a, m_per_k, sideways)
    render_s = time.perf_counter() - t0
    by_reach = {}  # rendered from the heights the clear-sky reference gives at each reach, at the law
    heights = {}
    for reach in reaches_px:
        ref = lift.reference_k(bt.astype(np.float32), good, reach)
        h = lift.height_above_m(bt.astype(np.float32), good, ref, m_per_k)
        heights[f"reference_{reach}px"] = _height_errors(h[good], height[good])
        by_reach[f"reference_{reach}px"] = render.render_height_field(
            np.where(good, x, np.nan), b, h, bt, a, m_per_k, sideways
        )
    geo_p = wgs84.geodetic_to_ecef(lat, lon, np.zeros(shape))
    source = _shift_columns(x, b, a, height, good, hit_p, geo_p, sideways)
    next_column = np.roll(geo_p, -1, axis=1) - geo_p  # the scan's way at the GEO point
    next_column[:, -1] = np.nan
    across_good = good & np.roll(good, -1, axis=1)
    sixth = np.broadcast_to((np.arange(shape[1]) * SIXTHS // shape[1])[None, :], shape)[good]
    p = geo_p[good]
    centres = p[np.random.default_rng(1).choice(len(p), 400, replace=False)]
    discs = cKDTree(p).query_ball_point(centres, DISC_M)
    detector = np.broadcast_to((np.arange(shape[0]) % VIIRS_DETECTORS)[:, None], shape)[good]
    edge = np.isin(detector, EDGE_DETECTORS)
    row: dict = {"commit": commit(), "clouds": clouds, "edges": edges, "seed": seed, "scans": scans}
    row["across"] = across
    row |= {"m_per_k": m_per_k, "render_s": render_s} | ({"heights": heights} if heights else {})
    for j, alpha in enumerate(ALPHA_RAD):
        t_view = view_time(sim, p, times[good], alpha)
        r_view, _, _ = sim.state(t_view)
        _, v_lat, v_lon, v_hit = sim.scene.intersect(r_view, frames.unit(p - r_view), unix_s=t_view)
        v_h = sim.scene.height_m(v_lat, v_lon)
        truth = band_bt(sim, sim.scene.temperature_k(v_lat, v_lon, v_h, t_view))
        e = next_column[good]
        cols = np.einsum("nk,nk->n", source[j][good] - wgs84.geodetic_to_ecef(v_lat, v_lon, v_hit), e)
        cols = cols / np.einsum("nk,nk->n", e, e)
        counted = across_good[good] & (v_hit > CLOUD_M) & np.isfinite(cols)
        shift = []
        for part in range(SIXTHS):
            c = cols[counted & (sixth == part)]
            q = np.percentile(c, [50, 16, 84]) if len(c) else np.full(3, np.nan)
            shift.append({"median": round(float(q[0]), 4), "p16": round(float(q[1]), 3),
                          "p84": round(float(q[2]), 3), "n": int(len(c))})  # fmt: skip
        out: dict = {}
        fields = {"render": rendered[j][good].astype(float), "geo": bt[good]}
        fields |= {name: v[j][good].astype(float) for name, v in by_reach.items()}
        for name, field in fields.items():
            err = field - truth
            disc = [np.nanmean(err[d]) for d in discs if len(d) > 500]
            off = np.abs(err) > 5.0
            out[name] = {
                "pixel_rms_k": float(np.sqrt(np.nanmean(err**2))),
                "disc_rms_k": float(np.sqrt(np.nanmean(np.square(disc)))),
                "off_5k_scan_edges": float(np.mean(off[edge])),
                "off_5k_scan_middle": float(np.mean(off[~edge])),
                "nan": float(np.mean(~np.isfinite(field))),
            }
        out["cross_track_columns"] = shift
        row[f"alpha_{alpha * 1e3:+.1f}_mrad"] = out
    return row


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--clouds", default="lapse:6.5")
    p.add_argument("--edges", default="sharp")
    p.add_argument("--seed", type=int, default=11)
    p.add_argument("--scans", type=int, default=8)
    p.add_argument(
        "--reaches",
        default="",
        help="comma-separated reaches (pixels) of the clear-sky reference to render from as well",
    )
    p.add_argument("--across", action="store_true", help="take each ray's BT at its own cross-track position")
    p.add_argument("--rows", help="append the JSON row here")
    args = p.parse_args()
    if args.clouds == "ground":
        p.error("--clouds ground: nothing stands above the ground to render")
    try:
        reaches = tuple(int(v) for v in args.reaches.split(",") if v)
    except ValueError:
        p.error(f"--reaches {args.reaches!r}: not comma-separated whole numbers of pixels")
    emit(measure(args.clouds, args.edges, args.seed, args.scans, reaches, args.across), args.rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
