"""The LOS perturbation assessment of Wang et al. 2017 (sections 2.3-2.4) of CrIS and VIIRS granules.

For each CrIS granule: inverse geolocation of every FOV to the SBF, the (2n+1)^2 perturbed cones (and,
with the ``footprint`` kernel, the annuli about them) collocated with VIIRS I5
(:mod:`monitor.collocation.collocate`),
and the CrIS I5-equivalent BT (:mod:`monitor.instrument.spectral`). Then per scan position k over all samples
the
estimator (:mod:`monitor.estimation.estimate`): the minimum of the cost (equation 8, G(i, j, k) =
STDEV(BT_VIIRS_ij -
BT_CrIS), or its regression form), the response fitted with the ``footprint`` kernel, the jackknife
uncertainty with a floor calibrated on simulated cases in quadrature (what the estimator itself leaves,
``estimate.SIGMA_FLOOR_URAD``; ``benchmarks/acceptance.py`` measures it), the intercalibration; and
here, the offsets in km on the ground.
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from monitor.collocation import collocate, swath
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import FOV_DIAMETER_RAD, N_FOR
from monitor.core.errors import AssessmentError, StopRequested
from monitor.core.result import AssessmentResult, GranuleInfo, Skipped
from monitor.core.threads import parallel_threads
from monitor.core.vocabulary import Kernel
from monitor.estimation.estimate import ForSamples, day_offsets
from monitor.geometry.ground import offset_km
from monitor.geometry.instrument import FOV5
from monitor.geometry.inverse import FovGeometry, granule_geometry
from monitor.geometry.perturb import perturbation_grid
from monitor.instrument.spectral import I5Band, i5_band
from monitor.sdr import (
    CrisGeoGranule,
    CrisSdrGranule,
    GranuleError,
    ViirsGeoGranule,
    ViirsSdrGranule,
    read_file,
)
from monitor.sdr.pairing import CasePlan, GranuleFiles, neighbours, plan
from monitor.sdr.readers import read_scan_start_us, read_viirs_geo_scan

LOG = logging.getLogger("monitor.assess")  # the name journal filters know, kept

Timings = dict[str, float] | None  # seconds per stage, added to when a dict
Span = tuple[int, int]  # IET (us) from, to
StopCheck = Callable[[], bool] | None  # polled; True: stop
Progress = Callable[["GranuleFiles"], object] | None  # called after each granule
# a VIIRS granule read: GEO, SDR, and the neighbours' adjacent scans (lat_rad, lon_rad, height_m) or None
RawViirs = tuple[
    ViirsGeoGranule, ViirsSdrGranule, tuple[np.ndarray, ...] | None, tuple[np.ndarray, ...] | None
]
# the discs each kernel collocates; the top-hat cone is one of them either way
KERNELS = {Kernel.TOP_HAT: collocate.TOP_HAT, Kernel.FOOTPRINT: collocate.ANNULI}
CONE_RADIUS_RAD = FOV_DIAMETER_RAD / 2


def offsets_rad(cfg: AssessmentConfig) -> np.ndarray:
    """The perturbation angles (rad) of one axis of the grid, -half_steps..+half_steps steps."""
    return perturbation_grid(cfg.half_steps, cfg.step_rad)


@dataclass
class GranuleSamples:
    """Collocated samples of one CrIS granule: per FOV the VIIRS BT of every perturbed cone."""

    key: str
    info: GranuleInfo
    bt_viirs_k: np.ndarray  # (nscan, 30, 9, m, m) through the top-hat cone
    bt_cris_k: np.ndarray  # (nscan, 30, 9)
    usable: np.ndarray  # (nscan, 30, 9)
    sat_m: np.ndarray  # FOV-5 geometry per (nscan, 30) for the km conversion
    sbf_to_ecef: np.ndarray
    alpha_rad: np.ndarray
    beta_rad: np.ndarray
    velocity_m_s: np.ndarray
    annuli_rad: np.ndarray | None = None  # (nscan, 30, 9, K, m, m) VIIRS radiance per annulus (footprint)


@contextmanager
def _stage(timings: Timings, name: str) -> Iterator[None]:
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


def _widen(span: Span | None, other: Span | None) -> Span | None:
    """The IET span covering both *span* and *other* (either may be None)."""
    if span is None or other is None:
        return other if span is None else span
    return (min(span[0], other[0]), max(span[1], other[1]))


def _reach_us(first_us: int, last_us: int) -> Span:
    """The IET span (us) of the VIIRS scans that CrIS observations from first_us to last_us may reach."""
    return (first_us - collocate.SCAN_TIME_MARGIN_US, last_us + collocate.SCAN_TIME_MARGIN_US)


def _scan_spans(cris: list[GranuleFiles], viirs: dict[str, list[GranuleFiles]]) -> dict[str, Span]:
    """Per VIIRS granule key, the IET span (us) of the scans the CrIS granules *cris* using it need (by
    their nominal bounds, :func:`_reach_us`): so that each is prepared once per run."""
    spans: dict[str, tuple[int, int]] = {}
    for g in cris:
        need = _reach_us(g.geo_meta.start_iet_us, g.geo_meta.end_iet_us)
        for v in viirs[g.key]:
            spans[v.key] = _widen(spans.get(v.key), need) or need  # (never None: need is a span)
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


def _read_viirs(v: GranuleFiles, viirs_all: list[GranuleFiles], span_us: Span | None = None) -> RawViirs:
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
    viirs: list[GranuleFiles],
    viirs_all: list[GranuleFiles],
    band: I5Band,
    cfg: AssessmentConfig,
    prepared: Iterable[str] = (),
    timings: Timings = None,
    spans: dict[str, Span] | None = None,
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
            offsets_rad(cfg),
            KERNELS[cfg.kernel],
        )
    return GranuleInputs(geo, sdr, fg, valid, fill, view_rad, span_us, bt_cris, raw)


def _run_span(spans: dict[str, Span], key: str, span_us: Span | None) -> Span | None:
    """The IET span of VIIRS granule *key* prepared for a CrIS granule reaching *span_us*: the run's span
    of that granule widened to it (None, every scan, when the CrIS granule has no observation time)."""
    return _widen(spans.get(key), span_us) if span_us is not None else None


def _piece(
    v: GranuleFiles,
    viirs_all: list[GranuleFiles],
    band: I5Band,
    cache: _SwathCache,
    view_rad: float,
    timings: Timings = None,
    raw: RawViirs | None = None,
    span_us: Span | None = None,
) -> swath.SwathPiece:
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
    assert geo.height_m is not None  # zeros for the ellipsoid product (ViirsGeoGranule)
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
    viirs_all: list[GranuleFiles],
    band: I5Band,
    cache: _SwathCache,
    view_rad: float,
    timings: Timings = None,
    raw: dict[str, RawViirs] | None = None,
    span_us: Span | None = None,
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
    cfg: AssessmentConfig,
    band: I5Band,
    cache: _SwathCache,
    timings: Timings = None,
    viirs_all: list[GranuleFiles] | None = None,
    should_stop: StopCheck = None,
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
        bt_viirs, coverage, annuli = _collocate_fors(pieces, geo, fg, valid, fill, cfg, band, should_stop)
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
        annuli,
    )


def _cris_geometry(geo: CrisGeoGranule) -> tuple[FovGeometry, np.ndarray, dict]:
    """Inverse geolocation of a CrIS GEO granule, with fill FOVs given harmless values and masked."""
    valid = geo.valid
    fill = {
        k: np.where(valid, getattr(geo, k), 0.0) for k in ("lat_rad", "lon_rad", "zenith_rad", "azimuth_rad")
    }
    return granule_geometry(geo), valid, fill


def _collocate_fors(
    pieces: swath.ViirsSwath,
    geo: CrisGeoGranule,
    fg: FovGeometry,
    valid: np.ndarray,
    fill: dict,
    cfg: AssessmentConfig,
    band: I5Band,
    should_stop: StopCheck = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """VIIRS BT (nscan, 30, 9, m, m) of every perturbed cone, the worst coverage per FOV (of the outermost
    disc), and with the footprint kernel the radiance per annulus (nscan, 30, 9, K, m, m), else None (all
    FOVs of the granule in one call of the parallel kernel)."""
    if should_stop is not None and should_stop():
        raise StopRequested
    m = len(offsets_rad(cfg))
    shape = fg.alpha_rad.shape
    cones = collocate.cone_sums(
        pieces,
        fg.sat_ecef_m.reshape(-1, 3),
        fg.sbf_to_ecef.reshape(-1, 3, 3),
        fg.alpha_rad.ravel(),
        fg.beta_rad.ravel(),
        offsets_rad(cfg),
        KERNELS[cfg.kernel],
        fov_range_m=np.where(valid, geo.range_m, 1e6).ravel(),
        fov_cos_zen=np.cos(fill["zenith_rad"]).ravel(),
    )
    cone = KERNELS[cfg.kernel].index(CONE_RADIUS_RAD)
    bt_viirs = band.bt_from_radiance(cones.mean(cone)).astype(np.float32).reshape(shape + (m, m))
    coverage = np.min(cones.coverage(), axis=(-2, -1)).reshape(shape)
    annuli = None
    if len(KERNELS[cfg.kernel]) > 1:
        annuli = cones.annulus_means().reshape(shape + (len(KERNELS[cfg.kernel]), m, m))
    return bt_viirs, coverage, annuli


def _ground_km(
    samples: list[GranuleSamples], k: int, d_alpha: float, d_beta: float
) -> tuple[float, float, np.ndarray]:
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


def for_samples(
    samples: list[GranuleSamples], k: int, cfg: AssessmentConfig, band: I5Band | None = None
) -> ForSamples:
    """The estimator's input for FOR k (0-based): every usable FOV of it over the granules (*band*, the
    satellite's I5 band, for the footprint kernel)."""
    m = len(offsets_rad(cfg))
    d, cris, granule, scan, annuli = [], [], [], [], []
    for g_i, s in enumerate(samples):
        use = s.usable[:, k]  # (nscan, 9)
        d.append((s.bt_viirs_k[:, k][use] - s.bt_cris_k[:, k][use][:, None, None]).astype(np.float64))
        cris.append(s.bt_cris_k[:, k][use].astype(np.float64))
        scans = np.nonzero(use)[0]  # the scan of each sample
        granule.append(np.full(scans.size, g_i))
        scan.append(scans)
        if s.annuli_rad is not None:
            annuli.append(s.annuli_rad[:, k][use])
    footprint = len(KERNELS[cfg.kernel]) > 1
    return ForSamples(
        np.concatenate(d) if d else np.empty((0, m, m)),
        np.concatenate(cris) if cris else np.empty(0),
        np.concatenate(granule) if granule else np.empty(0, int),
        np.concatenate(scan) if scan else np.empty(0, int),
        np.concatenate(annuli) if footprint and annuli else None,
        KERNELS[cfg.kernel] if footprint else (),
        band,
    )


def cost_and_offsets(
    samples: list[GranuleSamples],
    cfg: AssessmentConfig,
    skipped: Sequence[tuple[str, str]] | None = None,
    satellite: str = "",
) -> AssessmentResult:
    """The cost cube, per-FOR minimum, jackknife uncertainty and km offsets of collocated *samples*."""
    band = i5_band(satellite or samples[0].info.cris_meta["platform"]) if samples else None
    day = day_offsets(
        [for_samples(samples, k, cfg, band) for k in range(N_FOR)],
        cfg,
        cfg.step_urad,
        lambda k, d_alpha_rad, d_beta_rad: _ground_km(samples, k, d_alpha_rad, d_beta_rad),
    )
    starts = [s.info.start for s in samples]
    ends = [s.info.end for s in samples]
    return AssessmentResult(
        satellite=satellite,
        start=min(starts) if starts else "",
        end=max(ends) if ends else "",
        fors=day.fors,
        granules=[s.info for s in samples],
        skipped=[Skipped(str(a), str(b)) for a, b in (skipped or [])],
        half_steps=cfg.half_steps,
        step_urad=cfg.step_urad,
        cost_cube_k=day.cost_cube_k,
        difference_bins=day.difference_bins,
    )


def _collocate_run(
    cris: list[GranuleFiles],
    viirs: dict[str, list[GranuleFiles]],
    viirs_all: list[GranuleFiles],
    satellite: str,
    cfg: AssessmentConfig,
    progress: Progress = None,
    should_stop: StopCheck = None,
    timings: Timings = None,
) -> tuple[list[GranuleSamples], list[tuple[str, str]]]:
    """Collocate a time-ordered run of CrIS granules; returns (samples, skipped)."""
    band = i5_band(satellite)
    cache = _SwathCache(spans=_scan_spans(cris, viirs))
    samples, skipped = [], []
    reading: dict[str, float] = {}  # the read-ahead thread's seconds, added to *timings* at the end

    def read_ahead(i: int) -> cf.Future[GranuleInputs]:
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
    cfg: AssessmentConfig | None = None,
    progress: Progress = None,
    should_stop: StopCheck = None,
    timings: Timings = None,
    workers: int = 1,
) -> AssessmentResult:
    """Assess every CrIS granule of *case*; granules that fail are skipped with their reason. Fewer usable
    FOVs in all than ``cfg.min_samples`` is an :class:`AssessmentError` naming the files.

    *progress* is called after each granule; *should_stop* is polled before each and before the cost
    stage (a stop request ends the assessment with :class:`StopRequested`); *timings*, a dict, collects
    seconds per stage. *workers* is the number of threads of the compiled VIIRS preparation and
    collocation (granules go one after the other, each VIIRS granule prepared once).
    """
    cfg = cfg or AssessmentConfig()
    skipped = list(case.skipped)
    with parallel_threads(workers):
        samples, k = _collocate_run(
            case.cris, case.viirs, case.viirs_all, case.satellite, cfg, progress, should_stop, timings
        )
    skipped += k
    if should_stop is not None and should_stop():  # an interruption, not bad data: no cost stage either
        raise StopRequested
    usable = sum(int(s.usable.sum()) for s in samples)
    if usable < cfg.min_samples:
        files = ", ".join(sorted({s.info.cris_geo for s in samples} | {str(k) for k, _ in skipped}))[:800]
        why = "; ".join(f"{k}: {r}" for k, r in skipped[:3])
        raise AssessmentError(
            f"too few usable FOVs to assess: {usable} (at least {cfg.min_samples}) in "
            f"{len(samples)} granule(s) [{files}]" + (f"; skipped: {why}" if why else "")
        )
    with _stage(timings, "cost"):
        return cost_and_offsets(samples, cfg, skipped, case.satellite)


def assess_paths(
    paths: Sequence[str | Path],
    cfg: AssessmentConfig | None = None,
    progress: Progress = None,
    workers: int = 1,
) -> AssessmentResult:
    """Find, pair and assess the granules under *paths* (files or directories)."""
    return assess_plan(plan(paths), cfg, progress, workers=workers)
