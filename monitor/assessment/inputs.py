"""The inputs of a CrIS granule's assessment, read ahead of its collocation: its GEO and SDR, their inverse
geometry and band BT, the VIIRS granules it reaches read over the scans it needs (the scan overlap's halos
included) and prepared once per run as swath pieces (:mod:`monitor.collocation.swath`)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from monitor.collocation import collocate, reach, render, swath
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import VIIRS_DETECTORS
from monitor.core.vocabulary import Kernel
from monitor.geometry.inverse import FovGeometry, granule_geometry
from monitor.geometry.perturb import perturbation_grid
from monitor.instrument.spectral import BandModel
from monitor.sdr import (
    CrisGeoGranule,
    CrisSdrGranule,
    GranuleError,
    ViirsGeoGranule,
    ViirsSdrGranule,
    read_file,
)
from monitor.sdr.pairing import GranuleFiles, neighbours
from monitor.sdr.readers import read_scan_start_us, read_viirs_geo_scan

Timings = dict[str, float] | None  # seconds per stage, added to when a dict


Span = tuple[int, int]  # IET (us) from, to


# a VIIRS granule read: GEO, SDR, and the neighbours' adjacent scans (lat_rad, lon_rad, height_m) or None
RawViirs = tuple[
    ViirsGeoGranule, ViirsSdrGranule, tuple[np.ndarray, ...] | None, tuple[np.ndarray, ...] | None
]


# the discs each kernel collocates; the top-hat cone is one of them either way
KERNELS = {Kernel.TOP_HAT: collocate.TOP_HAT, Kernel.FOOTPRINT: collocate.ANNULI}


def offsets_rad(cfg: AssessmentConfig) -> np.ndarray:
    """The perturbation angles of one axis of the grid, -half_steps..+half_steps steps.

    Parameters
    ----------
    cfg : AssessmentConfig
        The grid (``half_steps``, ``step_urad``).

    Returns
    -------
    numpy.ndarray
        rad, shape (2n+1,).
    """
    return perturbation_grid(cfg.half_steps, cfg.step_rad)


@contextmanager
def stage(timings: Timings, name: str) -> Iterator[None]:
    """Add the wall time of the block to ``timings[name]`` when *timings* is a dict.

    Parameters
    ----------
    timings : dict or None
        Seconds per stage.
    name : str
        The stage.

    Returns
    -------
    iterator
        A context manager's one value, None.
    """
    t0 = time.perf_counter()
    try:
        yield
    finally:
        if timings is not None:
            timings[name] = timings.get(name, 0.0) + time.perf_counter() - t0


PieceVariant = Callable[[swath.SwathPiece], swath.SwathPiece]  # a study's change to a prepared piece


@dataclass
class SwathCache:
    """Prepared VIIRS granules (swath pieces) by key; the few most recent are kept. *spans* holds, by key,
    the IET span (us) of the VIIRS scans that the run's CrIS granules need (:func:`scan_spans`). With
    *lift_m_per_k* (m per K colder than the clear-sky reference: :mod:`monitor.collocation.lift`), every
    piece holds what each CrIS FOV row sees of its pixels standing at that height
    (*renderer*: :func:`monitor.collocation.render.rendered_bt`, or a study's through
    :class:`monitor.assessment.seam.Variation`); with 0, the pixels' own radiance. *piece*, None in the
    service, is a study's change to each piece as it is prepared (the pixels the cone kernel sees).
    *detectors*: the rows of a scan of the band's grid; *smoothed_cones*: the grid's cone sums are smoothed
    over neighbouring perturbations (:func:`monitor.collocation.sums.smoothed`)."""

    pieces: dict = field(default_factory=dict)
    # a CrIS granule's scans with their margins (32 + 2 x 16 s) reach at most two VIIRS granules (86 s):
    # a third kept would be one no granule of a time-ordered run needs again, at the peak's cost
    keep: int = 2
    spans: dict = field(default_factory=dict)
    lift_m_per_k: float = 0.0
    renderer: render.Renderer = render.rendered_bt
    piece: PieceVariant | None = None
    detectors: int = VIIRS_DETECTORS
    smoothed_cones: bool = False


def _widen(span: Span | None, other: Span | None) -> Span | None:
    """The IET span covering both *span* and *other* (either may be None)."""
    if span is None or other is None:
        return other if span is None else span
    return (min(span[0], other[0]), max(span[1], other[1]))


def reach_us(first_us: int, last_us: int) -> Span:
    """The span of the VIIRS scans that CrIS observations may reach.

    Parameters
    ----------
    first_us, last_us : int
        The first and last CrIS observation, IET us.

    Returns
    -------
    tuple of int
        (t0, t1), IET us, with :data:`collocate.SCAN_TIME_MARGIN_US` either side.
    """
    return (first_us - collocate.SCAN_TIME_MARGIN_US, last_us + collocate.SCAN_TIME_MARGIN_US)


def scan_spans(cris: list[GranuleFiles], viirs: dict[str, list[GranuleFiles]]) -> dict[str, Span]:
    """Per VIIRS granule, the span of the scans the CrIS granules using it need, so that each is prepared
    once.

    Parameters
    ----------
    cris : list of GranuleFiles
        The run's CrIS granules.
    viirs : dict of str to list of GranuleFiles
        Each CrIS granule's (by key) VIIRS granules.

    Returns
    -------
    dict of str to tuple of int
        VIIRS granule key to (t0, t1), IET us (by the CrIS granules' nominal bounds, :func:`reach_us`).
    """
    spans: dict[str, tuple[int, int]] = {}
    for g in cris:
        need = reach_us(g.geo_meta.start_iet_us, g.geo_meta.end_iet_us)
        for v in viirs[g.key]:
            spans[v.key] = _widen(spans.get(v.key), need) or need  # (never None: need is a span)
    return spans


@dataclass
class GranuleInputs:
    """What one CrIS granule's assessment needs before its VIIRS granules are prepared: its GEO and SDR,
    their inverse geometry (fg, valid, fill: :func:`cris_geometry`), how far from nadir its cones reach
    (view_rad), the IET span (us) of the VIIRS scans they may reach (span_us, from its observation
    times: :func:`reach_us`; None when it has none), its band BT (bt_cris_k), and the raw VIIRS
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


def read_viirs(v: GranuleFiles, viirs_all: list[GranuleFiles], span_us: Span | None = None) -> RawViirs:
    """A VIIRS granule's GEO and SDR, with the adjacent scans of its neighbours (for the scan overlap).

    Parameters
    ----------
    v : GranuleFiles
        A VIIRS granule's SDR and GEO files.
    viirs_all : list of GranuleFiles
        Every VIIRS granule of the run.
    span_us : tuple of int, optional
        Read only what :func:`swath.swath_piece` uses of this span (IET us): the scans observed in it and one
        scan either side, and a neighbour's adjacent scan only where the span reaches the granule's edge.

    Returns
    -------
    RawViirs
        The GEO, the SDR and the neighbours' adjacent scans; rows outside the span hold fill (read in place,
        their bytes never travel).
    """
    scans = slice(None)
    if span_us is not None:
        start_us = read_scan_start_us(v.geo)
        first, stop, _ = reach.scans_between(start_us, *span_us).indices(len(start_us))
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
    band: BandModel,
    cfg: AssessmentConfig,
    prepared: Iterable[str] = (),
    timings: Timings = None,
    spans: dict[str, Span] | None = None,
) -> GranuleInputs:
    """Read what :func:`collocate_granule` needs of a CrIS granule, and compute what depends on it alone.

    Parameters
    ----------
    cris : GranuleFiles
        The CrIS granule's SDR and GEO files.
    viirs : list of GranuleFiles
        The VIIRS granules covering it.
    viirs_all : list of GranuleFiles
        Every VIIRS granule of the run.
    band : BandModel
        The assessed band (I5, or M15 on the M grid).
    cfg : AssessmentConfig
        The assessment's configuration.
    prepared : iterable of str
        VIIRS granule keys already prepared: not read again.
    timings : dict, optional
        Collects seconds per stage.
    spans : dict of str to tuple of int, optional
        The scans of the run per VIIRS granule (:func:`scan_spans`).

    Returns
    -------
    GranuleInputs
        The CrIS GEO and SDR, their geometry and band BT, the cones' reach and the raw VIIRS granules.
    """
    with stage(timings, "read"):
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
        span_us = reach_us(int(seen.min()), int(seen.max())) if seen.size else None
        raw = {
            v.key: read_viirs(v, viirs_all, _run_span(spans or {}, v.key, span_us))
            for v in viirs
            if v.key not in prepared
        }
    with stage(timings, "spectral"):
        bt_cris = band.bt_from_radiance(band.cris_band_radiance(np.nan_to_num(sdr.radiance_lw)))
    with stage(timings, "geometry"):
        fg, valid, fill = cris_geometry(geo)
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


def piece(
    v: GranuleFiles,
    viirs_all: list[GranuleFiles],
    band: BandModel,
    cache: SwathCache,
    view_rad: float,
    timings: Timings = None,
    raw: RawViirs | None = None,
    span_us: Span | None = None,
) -> swath.SwathPiece:
    """A VIIRS granule prepared out to at least *view_rad* from nadir, from the cache or prepared now.

    Parameters
    ----------
    v : GranuleFiles
        A VIIRS granule's SDR and GEO files.
    viirs_all : list of GranuleFiles
        Every VIIRS granule of the run.
    band : BandModel
        The assessed band (I5, or M15 on the M grid).
    cache : SwathCache
        The run's prepared granules.
    view_rad : float
        The view angle from nadir the cones reach, rad.
    timings : dict, optional
        Collects seconds per stage.
    raw : RawViirs, optional
        The granule as read ahead; read here when None.
    span_us : tuple of int, optional
        The IET span whose scans are needed (None: all).

    Returns
    -------
    SwathPiece
        Prepared out to view_rad + :data:`VIEW_MARGIN_RAD` (so that the next CrIS granule's slightly wider
        reach finds it ready) with the scans the whole run needs; with the cache's lift, rendered for the
        in-track angles :data:`monitor.collocation.render.VIEW_ALPHA_RAD`.
    """
    cached = cache.pieces.get(v.key)
    if cached is not None and cached.view_rad >= view_rad and (span_us is None or cached.covers(*span_us)):
        return cached
    cache.pieces.pop(v.key, None)
    run_span = _run_span(cache.spans, v.key, span_us)
    if raw is None:
        with stage(timings, "read"):
            raw = read_viirs(v, viirs_all, run_span)
    geo, sdr, halo_before, halo_after = raw
    assert geo.height_m is not None  # zeros for the ellipsoid product (ViirsGeoGranule)
    reach_rad = view_rad + collocate.VIEW_MARGIN_RAD
    seen = None
    if cache.lift_m_per_k:
        with stage(timings, "parallax"):
            # what the piece keeps, and a scan either side: a ray's stretches lie within ~1 km of its foot
            scans, columns = reach.kept_pixels(
                geo.lat_rad, geo.lon_rad, geo.height_m, geo.sc_position_m, reach_rad,
                geo.start_time_us, run_span, cache.detectors,
            )  # fmt: skip
            first, stop, _ = scans.indices(len(geo.sc_position_m))
            seen = cache.renderer(
                geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good, geo.sc_position_m,
                geo.sc_velocity_m_s, render.VIEW_ALPHA_RAD, cache.lift_m_per_k,
                slice(max(first - 1, 0), stop + 1), columns, cache.detectors,
            )  # fmt: skip
    with stage(timings, "geometry"):
        piece = swath.swath_piece(
            geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good, band, halo_before, halo_after,
            sat_m=geo.sc_position_m, view_rad=reach_rad, scan_start_us=geo.start_time_us, span_us=run_span,
            seen_bt_k=seen, view_alpha_rad=render.VIEW_ALPHA_RAD, detectors=cache.detectors,
        )  # fmt: skip
    if cache.piece is not None:
        piece = cache.piece(piece)
    while len(cache.pieces) >= cache.keep:
        cache.pieces.pop(next(iter(cache.pieces)))
    cache.pieces[v.key] = piece
    return piece


def load_swath(
    viirs: list[GranuleFiles],
    viirs_all: list[GranuleFiles],
    band: BandModel,
    cache: SwathCache,
    view_rad: float,
    timings: Timings = None,
    raw: dict[str, RawViirs] | None = None,
    span_us: Span | None = None,
) -> swath.ViirsSwath:
    """The prepared VIIRS granules covering one CrIS granule, each prepared once and kept in the cache.

    Parameters
    ----------
    viirs : list of GranuleFiles
        The VIIRS granules covering it.
    viirs_all : list of GranuleFiles
        Every VIIRS granule of the run.
    band : BandModel
        The assessed band (I5, or M15 on the M grid).
    cache : SwathCache
        The run's prepared granules.
    view_rad : float
        The view angle from nadir the cones reach, rad.
    timings : dict, optional
        Collects seconds per stage.
    raw : dict of str to RawViirs, optional
        Granules read ahead, by key (:func:`read_viirs`).
    span_us : tuple of int, optional
        The IET span whose scans are needed.

    Returns
    -------
    ViirsSwath
        The pieces.
    """
    raw = raw or {}
    # a time-ordered run never needs again a piece this granule does not: freed before the new ones are
    # prepared, it does not add to the peak
    for key in [k for k in cache.pieces if k not in {v.key for v in viirs}]:
        del cache.pieces[key]
    return swath.ViirsSwath(
        [piece(v, viirs_all, band, cache, view_rad, timings, raw.get(v.key), span_us) for v in viirs]
    )


def cris_geometry(geo: CrisGeoGranule) -> tuple[FovGeometry, np.ndarray, dict]:
    """The inverse geolocation of a CrIS GEO granule, with fill FOVs given harmless values and masked.

    Parameters
    ----------
    geo : CrisGeoGranule
        The granule.

    Returns
    -------
    geometry : FovGeometry
        :func:`monitor.geometry.inverse.granule_geometry`.
    valid : numpy.ndarray
        Where a FOV is geolocated.
    fill : dict
        The FOV fields with fill replaced.
    """
    valid = geo.valid
    fill = {
        k: np.where(valid, getattr(geo, k), 0.0) for k in ("lat_rad", "lon_rad", "zenith_rad", "azimuth_rad")
    }
    return granule_geometry(geo), valid, fill
