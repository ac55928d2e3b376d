"""The LOS perturbation assessment of Wang et al. 2017 (sections 2.3-2.4): cost cube, minimum, uncertainty.

For each CrIS granule: inverse geolocation of every FOV to the SBF, the (2n+1)^2 perturbed cones
collocated with VIIRS I5 (:mod:`monitor.collocate`), and the CrIS I5-equivalent BT (:mod:`monitor.spectral`).
Then per scan position k over all samples (equation 8):

    G(i, j, k) = STDEV(BT_VIIRS_ij - BT_CrIS),

its minimum refined between grid points by interpolating every sample's difference (:mod:`monitor.refine`;
the quadratic surface of Wang 2013 through the 3x3 neighbourhood only where the grid minimum is too near
the border for that), and its uncertainty: a bootstrap over scans within granules (the scatter) and a
floor calibrated on simulated cases (what the estimator itself leaves, ``AssessConfig.sigma_floor_urad``;
``benchmarks/acceptance.py`` measures it).
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from monitor import collocate, refine, swath
from monitor.constants import DEFAULT_HALF_STEPS, DEFAULT_STEP_RAD, N_FOR, URAD
from monitor.errors import AssessmentError, StopRequested
from monitor.geometry.ground import offset_km
from monitor.geometry.instrument import FOV5
from monitor.geometry.inverse import FovGeometry, granule_geometry
from monitor.geometry.perturb import perturbation_grid
from monitor.intercal import NO_FIT, difference_bins, intercalibrate
from monitor.result import (
    FLAG_EDGE,
    FLAG_FEW_SAMPLES,
    FLAG_FLAT,
    FLAG_UNCERTAIN,
    AssessmentResult,
    ForOffset,
    GranuleInfo,
)
from monitor.sdr import CrisGeoGranule, CrisSdrGranule, GranuleError, read_file
from monitor.sdr.pairing import CasePlan, GranuleFiles, neighbours, plan
from monitor.sdr.readers import read_scan_start_us, read_viirs_geo_scan
from monitor.spectral import i5_band
from monitor.threads import parallel_threads
from monitor.vocabulary import DEFAULT_COST, Cost

LOG = logging.getLogger(__name__)
KERNELS = {"top-hat": collocate.TOP_HAT, "response": collocate.SPATIAL_RESPONSE}


@dataclass
class AssessConfig:
    """Settings of one assessment. The defaults are the paper's but the cost's (``DEFAULT_COST``: the
    regression form of equation 8, chosen by measurement)."""

    half_steps: int = DEFAULT_HALF_STEPS
    step_rad: float = DEFAULT_STEP_RAD
    kernel: str = "top-hat"
    cost: Cost = DEFAULT_COST
    min_coverage: float = collocate.MIN_COVERAGE
    min_samples: int = 30
    flat_contrast: float = 0.03
    max_sigma_urad: float = 250.0  # ~0.55 perturbation step, 1.5 % of the FOV
    bootstrap: int = 100
    seed: int = 0
    sigma_floor_urad: float = 5.0  # in quadrature with the bootstrap: the estimator's own error (calibrated)

    @classmethod
    def of(cls, half_steps: int, step_urad: float, kernel: str, cost: Cost = DEFAULT_COST) -> AssessConfig:
        """The assessment of a configuration's (or the command line's) grid, kernel and cost, the rest
        the paper's."""
        return cls(half_steps=half_steps, step_rad=step_urad * URAD, kernel=kernel, cost=Cost(cost))

    @property
    def offsets_rad(self) -> np.ndarray:
        """The perturbation angles (rad) of one axis of the grid, -half_steps..+half_steps steps."""
        return perturbation_grid(self.half_steps, self.step_rad)


@dataclass
class GranuleSamples:
    """Collocated samples of one CrIS granule: per FOV the VIIRS BT of every perturbed cone."""

    key: str
    info: GranuleInfo
    bt_viirs_k: np.ndarray  # (nscan, 30, 9, m, m)
    bt_cris_k: np.ndarray  # (nscan, 30, 9)
    usable: np.ndarray  # (nscan, 30, 9)
    sat_m: np.ndarray  # FOV-5 geometry per (nscan, 30) for the km conversion
    sbf_to_ecef: np.ndarray
    alpha_rad: np.ndarray
    beta_rad: np.ndarray
    velocity_m_s: np.ndarray


@contextmanager
def _stage(timings, name):
    """Add the wall time of the block to timings[name] (seconds) when *timings* is a dict."""
    t0 = time.perf_counter()
    try:
        yield
    finally:
        if timings is not None:
            timings[name] = timings.get(name, 0.0) + time.perf_counter() - t0


@dataclass
class _SwathCache:
    """Prepared VIIRS granules (swath pieces) by key; the few most recent are kept. *spans* holds, by key,
    the IET span (us) of the VIIRS scans that the run's CrIS granules need (:func:`_scan_spans`)."""

    pieces: dict = field(default_factory=dict)
    keep: int = 3
    spans: dict = field(default_factory=dict)


def _widen(span, other):
    """The IET span covering both *span* and *other* (either may be None)."""
    if span is None or other is None:
        return other if span is None else span
    return (min(span[0], other[0]), max(span[1], other[1]))


def _reach_us(first_us: int, last_us: int) -> tuple:
    """The IET span (us) of the VIIRS scans that CrIS observations from first_us to last_us may reach."""
    return (first_us - collocate.SCAN_TIME_MARGIN_US, last_us + collocate.SCAN_TIME_MARGIN_US)


def _scan_spans(cris: list, viirs: dict) -> dict:
    """Per VIIRS granule key, the IET span (us) of the scans the CrIS granules *cris* using it need (by
    their nominal bounds, :func:`_reach_us`): so that each is prepared once per run."""
    spans: dict[str, tuple[int, int]] = {}
    for g in cris:
        need = _reach_us(g.geo_meta.start_iet_us, g.geo_meta.end_iet_us)
        for v in viirs[g.key]:
            spans[v.key] = _widen(spans.get(v.key), need)
    return spans


@dataclass
class GranuleInputs:
    """What one CrIS granule's assessment needs before its VIIRS granules are prepared: its GEO and SDR,
    their inverse geometry (fg, valid, fill: :func:`_cris_geometry`), how far from nadir its cones reach
    (view_rad), the IET span (us) of the VIIRS scans they may reach (span_us, from its observation
    times: :func:`_reach_us`; None when it has none), its band BT (bt_cris_k), and the raw VIIRS
    granules (key -> (GEO, SDR, scan before, scan after)) not yet prepared."""

    geo: CrisGeoGranule
    sdr: CrisSdrGranule
    fg: FovGeometry
    valid: np.ndarray
    fill: dict
    view_rad: float
    span_us: tuple | None
    bt_cris_k: np.ndarray
    viirs: dict = field(default_factory=dict)


def _read_viirs(v: GranuleFiles, viirs_all: list, span_us=None):
    """A VIIRS granule's GEO and SDR, with the adjacent scans of its neighbours (for the scan overlap).

    Given *span_us* (IET us), only what :func:`swath.swath_piece` uses of that span is read: the scans
    observed in it and one scan either side (their halos), and a neighbour's adjacent scan only where the
    span reaches the granule's edge. The other rows hold fill; read in place, their bytes never travel."""
    scans = slice(None)
    if span_us is not None:
        start_us = read_scan_start_us(v.geo)
        first, stop, _ = swath.scans_between(start_us, *span_us).indices(len(start_us))
        scans = slice(max(first - 1, 0), min(stop + 1, len(start_us)))
    before, after = neighbours(viirs_all, v)
    geo = read_file(v.geo, kinds=("viirs_geo",), scans=scans)[0]
    sdr = read_file(v.sdr, kinds=("viirs_sdr",), scans=scans)[0]
    n_scans = len(geo.start_time_us)
    edge_before, edge_after = scans.indices(n_scans)[0] == 0, scans.indices(n_scans)[1] == n_scans
    halo_before = read_viirs_geo_scan(before.geo, -1) if before is not None and edge_before else None
    halo_after = read_viirs_geo_scan(after.geo, 0) if after is not None and edge_after else None
    if sdr.bt_k.shape != geo.lat_rad.shape:
        raise GranuleError(
            v.sdr,
            "BrightnessTemperature",
            f"shape {sdr.bt_k.shape} does not match the GEO {geo.lat_rad.shape}",
        )
    return geo, sdr, halo_before, halo_after


def read_inputs(
    cris: GranuleFiles,
    viirs: list,
    viirs_all: list,
    band,
    cfg: AssessConfig,
    prepared=(),
    timings=None,
    spans=None,
) -> GranuleInputs:
    """Read what :func:`collocate_granule` needs of *cris*, except the VIIRS granules in *prepared*, and
    compute what depends on the CrIS granule alone (its geometry and band BT). A VIIRS granule is read
    over its scans of the run (*spans*, by key: :func:`_scan_spans`) and of this granule's reach."""
    with _stage(timings, "read"):
        geo = next(
            g
            for g in read_file(cris.geo, kinds=("cris_geo",))
            if g.meta.granule_id == cris.geo_meta.granule_id
        )
        sdr = next(
            g
            for g in read_file(cris.sdr, kinds=("cris_sdr",))
            if g.meta.granule_id == cris.sdr_meta.granule_id
        )
        if sdr.radiance_lw.shape[:3] != geo.lat_rad.shape:
            raise GranuleError(
                cris.sdr,
                "ES_RealLW",
                f"shape {sdr.radiance_lw.shape[:3]} does not match the GEO {geo.lat_rad.shape}",
            )
        seen = geo.for_time_us[geo.for_time_us > 0]
        span_us = _reach_us(int(seen.min()), int(seen.max())) if seen.size else None
        raw = {
            v.key: _read_viirs(v, viirs_all, _run_span(spans or {}, v.key, span_us))
            for v in viirs
            if v.key not in prepared
        }
    with _stage(timings, "spectral"):
        bt_cris = band.bt_from_radiance(band.cris_band_radiance(np.nan_to_num(sdr.radiance_lw)))
    with _stage(timings, "geometry"):
        fg, valid, fill = _cris_geometry(geo)
        view_rad = collocate.view_reach_rad(
            fg.sat_ecef_m[valid],
            fg.sbf_to_ecef[valid],
            fg.alpha_rad[valid],
            fg.beta_rad[valid],
            cfg.offsets_rad,
            KERNELS[cfg.kernel],
        )
    return GranuleInputs(geo, sdr, fg, valid, fill, view_rad, span_us, bt_cris, raw)


def _run_span(spans: dict, key: str, span_us):
    """The IET span of VIIRS granule *key* prepared for a CrIS granule reaching *span_us*: the run's span
    of that granule widened to it (None, every scan, when the CrIS granule has no observation time)."""
    return _widen(spans.get(key), span_us) if span_us is not None else None


def _piece(
    v: GranuleFiles, viirs_all: list, band, cache: _SwathCache, view_rad, timings=None, raw=None, span_us=None
):
    """The granule prepared out to at least *view_rad* from nadir, with its scans of the IET span
    *span_us* (None: all): from the cache, or prepared out to view_rad + VIEW_MARGIN_RAD (so that the next
    CrIS granule's slightly wider reach finds it ready) with the scans the whole run needs."""
    cached = cache.pieces.get(v.key)
    if cached is not None and cached.view_rad >= view_rad and (span_us is None or cached.covers(*span_us)):
        return cached
    cache.pieces.pop(v.key, None)
    run_span = _run_span(cache.spans, v.key, span_us)
    if raw is None:
        with _stage(timings, "read"):
            raw = _read_viirs(v, viirs_all, run_span)
    geo, sdr, halo_before, halo_after = raw
    with _stage(timings, "geometry"):
        piece = swath.swath_piece(
            geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good, band, halo_before, halo_after,
            sat_m=geo.sc_position_m, view_rad=view_rad + collocate.VIEW_MARGIN_RAD,
            scan_start_us=geo.start_time_us, span_us=run_span,
        )  # fmt: skip
    while len(cache.pieces) >= cache.keep:
        cache.pieces.pop(next(iter(cache.pieces)))
    cache.pieces[v.key] = piece
    return piece


def _load_swath(
    viirs: list[GranuleFiles],
    viirs_all: list,
    band,
    cache: _SwathCache,
    view_rad,
    timings=None,
    raw=None,
    span_us=None,
) -> swath.ViirsSwath:
    """The prepared VIIRS granules covering one CrIS granule (each prepared once, kept in *cache*) out
    to *view_rad* from nadir and over the IET span *span_us*, from the raw granules in *raw* (key ->
    :func:`_read_viirs`) or read here."""
    raw = raw or {}
    return swath.ViirsSwath(
        [_piece(v, viirs_all, band, cache, view_rad, timings, raw.get(v.key), span_us) for v in viirs]
    )


def collocate_granule(
    cris: GranuleFiles,
    viirs: list[GranuleFiles],
    cfg: AssessConfig,
    band,
    cache: _SwathCache,
    timings=None,
    viirs_all=None,
    should_stop=None,
    inputs: GranuleInputs | None = None,
) -> GranuleSamples:
    """Collocate every FOV of one CrIS granule for every perturbation with its VIIRS cover.

    *inputs* is what :func:`read_inputs` read ahead (read here when None); *timings*, when a dict,
    accumulates seconds per stage: read, geometry, spectral, collocation.
    """
    viirs_all = viirs_all or viirs
    if inputs is None:
        inputs = read_inputs(cris, viirs, viirs_all, band, cfg, tuple(cache.pieces), timings, cache.spans)
    geo, sdr, fg, valid, fill, bt_cris = (
        inputs.geo, inputs.sdr, inputs.fg, inputs.valid, inputs.fill, inputs.bt_cris_k
    )  # fmt: skip
    pieces = _load_swath(
        viirs, viirs_all, band, cache, inputs.view_rad, timings, inputs.viirs, inputs.span_us
    )
    with _stage(timings, "collocation"):
        bt_viirs, coverage = _collocate_fors(pieces, geo, fg, valid, fill, cfg, band, should_stop)
    usable = (
        valid
        & sdr.good
        & np.isfinite(bt_cris)
        & (coverage >= cfg.min_coverage)
        & np.all(np.isfinite(bt_viirs), axis=(-2, -1))
    )
    info = GranuleInfo(
        granule_id=geo.meta.granule_id,
        start=geo.meta.start.isoformat(),
        end=geo.meta.end.isoformat(),
        cris_geo=cris.geo.name,
        cris_sdr=cris.sdr.name,
        viirs=[v.sdr.name for v in viirs] + [v.geo.name for v in viirs],
        n_fovs=int(valid.sum()),
        n_usable=int(usable.sum()),
        cris_meta=geo.meta.to_dict(),
        viirs_meta=viirs[0].geo_meta.to_dict(),
    )
    s5 = (slice(None), slice(None), FOV5)
    return GranuleSamples(
        cris.key,
        info,
        bt_viirs,
        bt_cris,
        usable,
        fg.sat_ecef_m[s5],
        fg.sbf_to_ecef[s5],
        fg.alpha_rad[s5],
        fg.beta_rad[s5],
        fg.velocity_ecef_m_s[s5],
    )


def _cris_geometry(geo):
    """Inverse geolocation of a CrIS GEO granule, with fill FOVs given harmless values and masked."""
    valid = geo.valid
    fill = {
        k: np.where(valid, getattr(geo, k), 0.0) for k in ("lat_rad", "lon_rad", "zenith_rad", "azimuth_rad")
    }
    return granule_geometry(geo), valid, fill


def _collocate_fors(pieces, geo, fg, valid, fill, cfg: AssessConfig, band, should_stop=None):
    """VIIRS BT (nscan, 30, 9, m, m) of every perturbed cone and the worst coverage per FOV (all FOVs of the
    granule in one call of the parallel kernel)."""
    if should_stop is not None and should_stop():
        raise StopRequested
    m = len(cfg.offsets_rad)
    shape = fg.alpha_rad.shape
    mean, cov = collocate.cone_sums(
        pieces,
        fg.sat_ecef_m.reshape(-1, 3),
        fg.sbf_to_ecef.reshape(-1, 3, 3),
        fg.alpha_rad.ravel(),
        fg.beta_rad.ravel(),
        cfg.offsets_rad,
        KERNELS[cfg.kernel],
        fov_range_m=np.where(valid, geo.range_m, 1e6).ravel(),
        fov_cos_zen=np.cos(fill["zenith_rad"]).ravel(),
    )
    bt_viirs = band.bt_from_radiance(mean).astype(np.float32).reshape(shape + (m, m))
    coverage = np.nanmin(np.where(np.isfinite(cov), cov, 0.0), axis=(-2, -1)).reshape(shape)
    return bt_viirs, coverage


def _stdev(d, weights=None):
    """STDEV over samples (axis 0 of d, (N, m, m)); with *weights* (B, N) one surface per row (B, m, m)."""
    n, m = d.shape[0], d.shape[1]
    flat = d.reshape(n, -1)
    if weights is None:
        return flat.std(axis=0, ddof=1).reshape(m, m)
    s0 = weights.sum(axis=1, keepdims=True)
    s1 = weights @ flat
    s2 = weights @ (flat * flat)
    var = (s2 - s1 * s1 / s0) / np.maximum(s0 - 1, 1)
    return np.sqrt(np.maximum(var, 0.0)).reshape(-1, m, m)


def calibration_regressors(cris):
    """The regressors of the regression cost (N, 2): the CrIS BT and its square about its mean, so that a
    CrIS-VIIRS difference bias + gain T + curvature T^2 is explained away."""
    c = np.asarray(cris, float) - np.mean(cris)
    return np.stack([c, c * c], axis=1)


def _regression_stdev(d, cris, weights=None):
    """The residual STDEV of d (N, m, m) regressed on the CrIS BT *cris* (N,) and its square, per
    perturbation: sqrt(Var d - s_dX S_XX^-1 s_Xd). With d = V - C this is the residual of V - f(C) for the
    best quadratic f at each perturbation, so a CrIS-VIIRS calibration difference up to second order
    leaves it unchanged. *weights* (B, N): one surface per bootstrap replicate (B, m, m)."""
    n, m = d.shape[0], d.shape[1]
    x = calibration_regressors(cris)
    flat = np.concatenate([d.reshape(n, -1), x], axis=1)
    w = np.ones((1, n)) if weights is None else np.asarray(weights, float)
    s0 = w.sum(axis=1)[:, None]
    mean = (w @ flat) / s0
    res = np.empty((len(w), m * m))
    for b in range(len(w)):  # one replicate at a time: (N, K) products stay small
        c = flat - mean[b]
        wc = c * w[b][:, None]
        var_d = np.einsum("nk,nk->k", wc[:, :-2], c[:, :-2])
        s_dx = wc[:, :-2].T @ c[:, -2:]  # (K, 2)
        s_xx = wc[:, -2:].T @ c[:, -2:]  # (2, 2)
        explained = np.einsum("ka,ab,kb->k", s_dx, np.linalg.inv(s_xx), s_dx)
        res[b] = (var_d - explained) / max(s0[b, 0] - 1, 1)
    g = np.sqrt(np.maximum(res, 0.0)).reshape(-1, m, m)
    return g[0] if weights is None else g


def cost_surface(d, cris, cost: Cost, weights=None):
    """The cost over the perturbation grid of one FOR's samples (:class:`~monitor.vocabulary.Cost`)."""
    return _stdev(d, weights) if cost == Cost.STDEV else _regression_stdev(d, cris, weights)


def find_minimum(cost, contrast=0.03):
    """Sub-step minimum (x_i, y_j in grid steps from the centre) of a cost surface, and its flags.

    A quadratic surface through the 3x3 neighbourhood of the grid minimum gives the sub-step position
    (Wang 2013). A minimum on the grid border is flagged ``edge`` and not refined; a surface that
    rises less than *contrast* (relative) from its minimum to the grid border, or whose fit is not
    convex, is flagged ``flat``.
    """
    m = cost.shape[0]
    n = (m - 1) // 2
    flags = []
    if not np.all(np.isfinite(cost)):
        return np.nan, np.nan, [FLAG_FLAT]
    i0, j0 = np.unravel_index(np.argmin(cost), cost.shape)
    border = np.concatenate([cost[0], cost[-1], cost[1:-1, 0], cost[1:-1, -1]])
    if (np.mean(border) - cost[i0, j0]) / cost[i0, j0] < contrast:
        flags.append(FLAG_FLAT)
    if i0 in (0, m - 1) or j0 in (0, m - 1):
        return float(i0 - n), float(j0 - n), flags + [FLAG_EDGE]
    x, y = np.meshgrid([-1.0, 0.0, 1.0], [-1.0, 0.0, 1.0], indexing="ij")
    a = np.stack([np.ones(9), x.ravel(), y.ravel(), x.ravel() ** 2, x.ravel() * y.ravel(), y.ravel() ** 2], 1)
    c = np.linalg.lstsq(a, cost[i0 - 1 : i0 + 2, j0 - 1 : j0 + 2].ravel(), rcond=None)[0]
    hess = np.array([[2 * c[3], c[4]], [c[4], 2 * c[5]]])
    if np.linalg.det(hess) <= 0 or hess[0, 0] <= 0:
        return float(i0 - n), float(j0 - n), sorted(set(flags + [FLAG_FLAT]))
    dx, dy = np.linalg.solve(hess, -c[1:3])
    dx, dy = float(np.clip(dx, -1, 1)), float(np.clip(dy, -1, 1))
    return i0 - n + dx, j0 - n + dy, flags


def _ground_km(samples: list[GranuleSamples], k: int, d_alpha, d_beta):
    """Mean in-track/cross-track km of a turn (rad) at FOR k over the FOV-5 views used, and the Jacobian."""
    sel = [
        (s.sat_m[:, k], s.sbf_to_ecef[:, k], s.alpha_rad[:, k], s.beta_rad[:, k], s.velocity_m_s[:, k])
        for s in samples
        if np.any(s.usable[:, k])
    ]
    if not sel:
        return np.nan, np.nan, np.full((2, 2), np.nan)
    sat, mat, a, b, v = (np.concatenate(x) for x in zip(*sel, strict=True))
    if not np.isfinite(d_alpha + d_beta):
        return np.nan, np.nan, np.full((2, 2), np.nan)
    it, ct = offset_km(sat, mat, a, b, v, d_alpha, d_beta)
    eps = 1e-4
    ja = offset_km(sat, mat, a, b, v, eps, 0.0)
    jb = offset_km(sat, mat, a, b, v, 0.0, eps)
    jac = np.array([[np.mean(ja[0]), np.mean(jb[0])], [np.mean(ja[1]), np.mean(jb[1])]]) / eps
    return float(np.mean(it)), float(np.mean(ct)), jac


def _scan_bootstrap_counts(rng, granule_of_unit, n_boot):
    """Bootstrap counts (B, units): each granule's scans resampled with replacement within the granule."""
    counts = np.zeros((n_boot, len(granule_of_unit)))
    for g in np.unique(granule_of_unit):
        members = np.flatnonzero(granule_of_unit == g)
        counts[:, members] = rng.multinomial(
            len(members), np.full(len(members), 1.0 / len(members)), size=n_boot
        )
    return counts


@dataclass
class ForMinimum:
    """The minimum of one FOR's cost surface *cost* (m, m): the offsets *x*, *y* (grid steps from the
    centre), their bootstrap sigmas (steps), flags; *d_opt* (N,) the samples' BT difference at the
    optimum, *refined* whether it lies between grid points (:mod:`monitor.refine`), *counts* (B, N) the
    bootstrap's resampling (None without one) and *d_opt_boot* (B, N) the difference at each replicate's
    optimum, so that what the intercalibration's sigma resamples includes where the optimum lies."""

    cost: np.ndarray
    x: float
    y: float
    sigma: tuple
    flags: list
    d_opt: np.ndarray
    refined: bool
    counts: np.ndarray | None
    d_opt_boot: np.ndarray | None  # (B, N): d at each replicate's own optimum (refined FORs), else None


def for_minimum(d, cris, unit_ids, granule_of_unit, cfg: AssessConfig, rng) -> ForMinimum:
    """Offsets, bootstrap sigmas and flags of one FOR, and its samples' BT difference at the optimum.

    *d* (N, m, m) holds the samples' BT differences, *cris* (N,) their CrIS BT, *unit_ids* (N,) the scan
    each comes from and *granule_of_unit* the granule of each scan. The cost surface is ``cfg.cost``'s
    over samples; its minimum is refined between grid points where the window fits (:mod:`monitor.refine`),
    and d is interpolated there with the refinement's own weights.
    """
    m = d.shape[1]
    regress = calibration_regressors(cris) if cfg.cost == Cost.REGRESSION else None
    g = cost_surface(d, cris, cfg.cost)
    x, y, flags = find_minimum(g, cfg.flat_contrast)
    i0, j0 = (int(k) for k in np.unravel_index(np.argmin(g), g.shape))
    fine = FLAG_EDGE not in flags and FLAG_FLAT not in flags and refine.refinable(i0, j0, m)
    d_opt = d[:, i0, j0]
    if fine:
        dx, dy = refine.refined_minimum(refine.window_covariance(d, i0, j0, cris=regress))
        x, y = i0 - (m - 1) // 2 + dx, j0 - (m - 1) // 2 + dy
        d_opt = refine.window_values(d, i0, j0, dx, dy)
    sig = (np.nan, np.nan)
    counts = d_boot = None
    if cfg.bootstrap > 1 and len(granule_of_unit) >= 2:
        counts = _scan_bootstrap_counts(rng, granule_of_unit, cfg.bootstrap)[:, unit_ids]
        if fine:
            est = refine.refined_minimum(refine.window_covariance(d, i0, j0, counts, regress))
            d_boot = refine.window_values(d, i0, j0, est[:, 0], est[:, 1])
        else:
            replicas = cost_surface(d, cris, cfg.cost, counts)
            est = np.array([find_minimum(s, cfg.flat_contrast)[:2] for s in replicas])
        sig = tuple(np.nanstd(est, axis=0))
    return ForMinimum(g, x, y, sig, flags, d_opt, fine, counts, d_boot)


def cost_and_offsets(
    samples: list[GranuleSamples], cfg: AssessConfig, skipped=None, satellite=""
) -> AssessmentResult:
    """The cost cube, per-FOR minimum, bootstrap uncertainty and km offsets of collocated *samples*."""
    offsets = cfg.offsets_rad
    m = len(offsets)
    step_urad = cfg.step_rad / URAD
    rng = np.random.default_rng(cfg.seed)
    cube = np.full((N_FOR, m, m), np.nan)
    fors = []
    pooled: list[tuple] = []  # (CrIS BT, VIIRS BT) at the optimum of each refined FOR: Figure 15's bins
    for k in range(N_FOR):
        diffs, cris_k, units = [], [], []
        for g_i, s in enumerate(samples):
            use = s.usable[:, k]  # (nscan, 9)
            d = s.bt_viirs_k[:, k][use] - s.bt_cris_k[:, k][use][:, None, None]
            diffs.append(d.astype(np.float64))
            cris_k.append(s.bt_cris_k[:, k][use].astype(np.float64))
            scans = np.nonzero(use)[0]  # the scan of each sample
            units.append(np.column_stack([np.full(scans.size, g_i), scans]))
        d = np.concatenate(diffs) if diffs else np.empty((0, m, m))
        # the scans (granule, scan) the samples come from, in order, and each sample's scan among them
        scan_keys, unit_ids = (
            np.unique(np.concatenate(units), axis=0, return_inverse=True)
            if diffs
            else (np.empty((0, 2), int), np.empty(0, int))
        )
        unit_ids = unit_ids.reshape(-1)
        n = len(d)
        flags = []
        if n < max(cfg.min_samples, 3):
            flags.append(FLAG_FEW_SAMPLES)
        x = y = np.nan
        sig_a = sig_b = np.nan
        g = np.full((m, m), np.nan)
        cal = NO_FIT
        if n >= 3:
            c = np.concatenate(cris_k)
            best = for_minimum(d, c, unit_ids, scan_keys[:, 0], cfg, rng)
            g, x, y, (sig_a, sig_b) = best.cost, best.x, best.y, best.sigma
            cube[k] = g
            flags += best.flags
            # the intercalibration at the optimum: V = d + C there
            cal = intercalibrate(
                c, best.d_opt + c, best.counts, None if best.d_opt_boot is None else best.d_opt_boot + c
            )
            if best.refined:
                pooled.append((c, best.d_opt + c))
            sig_a, sig_b = (
                np.hypot(sig_a * step_urad, cfg.sigma_floor_urad),
                np.hypot(sig_b * step_urad, cfg.sigma_floor_urad),
            )
            if max(sig_a, sig_b) > cfg.max_sigma_urad:
                flags.append(FLAG_UNCERTAIN)
        d_alpha, d_beta = x * step_urad, y * step_urad
        it, ct, jac = _ground_km(samples, k, d_alpha * 1e-6, d_beta * 1e-6)
        s_it = float(np.hypot(jac[0, 0] * sig_a, jac[0, 1] * sig_b) * 1e-6) if np.isfinite(sig_a) else np.nan
        s_ct = float(np.hypot(jac[1, 0] * sig_a, jac[1, 1] * sig_b) * 1e-6) if np.isfinite(sig_a) else np.nan
        fors.append(
            ForOffset(
                for_index=k + 1,
                d_alpha_urad=float(d_alpha),
                d_beta_urad=float(d_beta),
                sigma_alpha_urad=float(sig_a),
                sigma_beta_urad=float(sig_b),
                in_track_km=it,
                cross_track_km=ct,
                total_km=float(np.hypot(it, ct)),
                sigma_in_track_km=s_it,
                sigma_cross_track_km=s_ct,
                n_samples=int(n),
                cost_min_k=float(np.nanmin(g)) if n >= 3 else np.nan,
                cost_zero_k=float(g[m // 2, m // 2]) if n >= 3 else np.nan,
                bias_k=cal.bias_k,
                sigma_bias_k=cal.sigma_bias_k,
                gain_pct=cal.gain_pct,
                sigma_gain_pct=cal.sigma_gain_pct,
                curvature_k=cal.curvature_k,
                sigma_curvature_k=cal.sigma_curvature_k,
                flags=tuple(sorted(set(flags))),
            )
        )
    starts = [s.info.start for s in samples]
    ends = [s.info.end for s in samples]
    return AssessmentResult(
        satellite=satellite,
        start=min(starts) if starts else "",
        end=max(ends) if ends else "",
        fors=fors,
        granules=[s.info for s in samples],
        skipped=[{"item": a, "reason": b} for a, b in (skipped or [])],
        half_steps=cfg.half_steps,
        step_urad=step_urad,
        cost_cube_k=cube,
        difference_bins=difference_bins(*(np.concatenate(v) for v in zip(*pooled, strict=True)))
        if pooled
        else [],
    )


def _collocate_run(
    cris: list,
    viirs: dict,
    viirs_all: list,
    satellite: str,
    cfg: AssessConfig,
    progress=None,
    should_stop=None,
    timings=None,
):
    """Collocate a time-ordered run of CrIS granules; returns (samples, skipped)."""
    band = i5_band(satellite)
    cache = _SwathCache(spans=_scan_spans(cris, viirs))
    samples, skipped = [], []
    reading: dict[str, float] = {}  # the read-ahead thread's seconds, added to *timings* at the end

    def read_ahead(i):
        """Read granule i's inputs (and compute its CrIS geometry) in the background while granule i - 1
        is computed (h5py, numpy and the compiled kernels release the interpreter to each other)."""
        prepared = set(cache.pieces) | ({v.key for v in viirs[cris[i - 1].key]} if i else set())
        return pool.submit(
            read_inputs, cris[i], viirs[cris[i].key], viirs_all, band, cfg, prepared, reading, cache.spans
        )

    with cf.ThreadPoolExecutor(1, thread_name_prefix="crisgeo-read") as pool:
        ahead = read_ahead(0) if cris else None
        for i, g in enumerate(cris):
            current, ahead = ahead, None
            if should_stop is not None and should_stop():
                if current is not None:
                    current.cancel()
                skipped.append((g.key, "not assessed: stop requested"))
                continue
            if i + 1 < len(cris):
                ahead = read_ahead(i + 1)
            try:
                samples.append(
                    collocate_granule(
                        g,
                        viirs[g.key],
                        cfg,
                        band,
                        cache,
                        timings,
                        viirs_all,
                        should_stop,
                        current.result() if current is not None else None,
                    )
                )
            except StopRequested:
                skipped.append((g.key, "not assessed: stop requested"))
                continue
            except GranuleError as exc:
                LOG.warning("skipping granule %s: %s", g.key, exc)
                skipped.append((g.key, str(exc)))
            if progress is not None:
                progress(g)
        if ahead is not None:
            ahead.cancel()
    if timings is not None:
        for name, sec in reading.items():
            timings[name] = timings.get(name, 0.0) + sec
    return samples, skipped


def assess_plan(
    case: CasePlan,
    cfg: AssessConfig | None = None,
    progress=None,
    should_stop=None,
    timings=None,
    workers: int = 1,
) -> AssessmentResult:
    """Assess every CrIS granule of *case*; granules that fail are skipped with their reason. Fewer usable
    FOVs in all than ``cfg.min_samples`` is an :class:`AssessmentError` naming the files.

    *progress* is called after each granule; *should_stop* is polled before each (a stop request
    skips the rest, recorded); *timings*, a dict, collects seconds per stage. *workers* is the number of
    threads of the compiled VIIRS preparation and collocation (granules go one after the other, each
    VIIRS granule prepared once).
    """
    cfg = cfg or AssessConfig()
    skipped = list(case.skipped)
    with parallel_threads(workers):
        samples, k = _collocate_run(
            case.cris, case.viirs, case.viirs_all, case.satellite, cfg, progress, should_stop, timings
        )
    skipped += k
    usable = sum(int(s.usable.sum()) for s in samples)
    stopped = should_stop is not None and should_stop()  # the caller records an interruption, not bad data
    if usable < cfg.min_samples and not stopped:
        files = ", ".join(sorted({s.info.cris_geo for s in samples} | {str(k) for k, _ in skipped}))[:800]
        why = "; ".join(f"{k}: {r}" for k, r in skipped[:3])
        raise AssessmentError(
            f"too few usable FOVs to assess: {usable} (at least {cfg.min_samples}) in "
            f"{len(samples)} granule(s) [{files}]" + (f"; skipped: {why}" if why else "")
        )
    with _stage(timings, "cost"):
        return cost_and_offsets(samples, cfg, skipped, case.satellite)


def assess_paths(paths, cfg: AssessConfig | None = None, progress=None, workers: int = 1) -> AssessmentResult:
    """Find, pair and assess the granules under *paths* (files or directories)."""
    return assess_plan(plan(paths), cfg, progress, workers=workers)
