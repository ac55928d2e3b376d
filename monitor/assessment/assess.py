"""The LOS perturbation assessment of Wang et al. 2017 (sections 2.3-2.4) of a day's CrIS and VIIRS granules.

For each CrIS granule, its inputs read ahead (:mod:`monitor.assessment.inputs`): the (2n+1)^2 perturbed cones
of every FOV (and, with the ``footprint`` kernel, the annuli about them) collocated with VIIRS I5
(:mod:`monitor.collocation.collocate`) against the CrIS I5-equivalent BT. Then per scan position k over all
samples the estimator (:mod:`monitor.estimation.estimate`): the minimum of the cost (equation 8, G(i, j, k) =
STDEV(BT_VIIRS_ij - BT_CrIS), or its regression form), the response fitted with the ``footprint`` kernel, the
jackknife uncertainty, the intercalibration, and the offsets in km on the ground
(:mod:`monitor.assessment.estimates`).
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from monitor.assessment.estimates import GranuleSamples, cost_and_offsets
from monitor.assessment.inputs import (
    KERNELS,
    GranuleInputs,
    SwathCache,
    Timings,
    load_swath,
    offsets_rad,
    read_inputs,
    scan_spans,
    stage,
)
from monitor.assessment.seam import SERVICE, Variation
from monitor.assessment.spool import Spool
from monitor.collocation import collocate, swath
from monitor.compiled.threads import parallel_threads
from monitor.config.assessment import AssessmentConfig
from monitor.core.bands import BANDS
from monitor.core.constants import FOV_HALF_ANGLE_RAD
from monitor.core.errors import AssessmentError, StopRequested
from monitor.core.result import SECOND_BAND, AssessmentResult, GranuleInfo
from monitor.estimation.band_pair import with_second_band
from monitor.geometry.ep_model import FOV5
from monitor.geometry.inverse import FovGeometry
from monitor.instrument.spectral import BandModel, band_model
from monitor.sdr import (
    CrisGeoGranule,
    GranuleError,
)
from monitor.sdr.pairing import CasePlan, GranuleFiles, plan

LOG = logging.getLogger(__name__)


StopCheck = Callable[[], bool] | None  # polled; True: stop


Progress = Callable[["GranuleFiles"], object] | None  # called after each granule


def collocate_granule(
    cris: GranuleFiles,
    viirs: list[GranuleFiles],
    cfg: AssessmentConfig,
    band: BandModel,
    cache: SwathCache,
    timings: Timings = None,
    viirs_all: list[GranuleFiles] | None = None,
    should_stop: StopCheck = None,
    inputs: GranuleInputs | None = None,
) -> GranuleSamples:
    """Collocate every FOV of one CrIS granule for every perturbation with its VIIRS cover.

    Parameters
    ----------
    cris : GranuleFiles
        The CrIS granule's SDR and GEO files.
    viirs : list of GranuleFiles
        The VIIRS I5 SDR and GEO granules covering it.
    cfg : AssessmentConfig
        The assessment's configuration (grid, kernel).
    band : BandModel
        The satellite's I5 band.
    cache : SwathCache
        The prepared VIIRS granules, shared by the run's CrIS granules.
    timings : dict, optional
        Collects seconds per stage (read, geometry, parallax, spectral, collocation, cost).
    viirs_all : list of GranuleFiles, optional
        Every VIIRS granule of the run, for the neighbours' adjacent scans.
    should_stop : callable, optional
        Polled before each granule; True ends the batch with :class:`StopRequested`.
    inputs : GranuleInputs, optional
        What :func:`read_inputs` read ahead; read here when None.

    Returns
    -------
    GranuleSamples
        Per FOV the VIIRS BT of every perturbed cone (K) beside the CrIS BT, and the rendered collocation when
        the cache holds a lift.
    """
    viirs_all = viirs_all or viirs
    if inputs is None:
        inputs = read_inputs(cris, viirs, viirs_all, band, cfg, tuple(cache.pieces), timings, cache.spans)
    geo, sdr, fg, valid, fill, bt_cris = (
        inputs.geo, inputs.sdr, inputs.fg, inputs.valid, inputs.fill, inputs.bt_cris_k
    )  # fmt: skip
    pieces = load_swath(viirs, viirs_all, band, cache, inputs.view_rad, timings, inputs.viirs, inputs.span_us)
    with stage(timings, "collocation"):
        cones = _collocate_fors(pieces, geo, fg, valid, fill, cfg, should_stop, cache.smoothed_cones)
    found = [_per_fov(c, fg, cfg, band) for c in (cones, cones.rendered) if c is not None]
    usable = [
        valid & sdr.good & np.isfinite(bt_cris) & (coverage >= cfg.min_coverage)
        & np.all(np.isfinite(bt_viirs), axis=(-2, -1))
        for bt_viirs, coverage, _ in found
    ]  # fmt: skip
    info = GranuleInfo(
        granule_id=geo.meta.granule_id,
        start=geo.meta.start.isoformat(),
        end=geo.meta.end.isoformat(),
        cris_geo=cris.geo.name,
        cris_sdr=cris.sdr.name,
        viirs=[v.sdr.name for v in viirs] + [v.geo.name for v in viirs],
        n_fovs=int(valid.sum()),
        n_usable=int(usable[0].sum()),
        cris_meta=geo.meta.to_dict(),
        viirs_meta=viirs[0].geo_meta.to_dict(),
    )
    s5 = (slice(None), slice(None), FOV5)
    samples = [
        GranuleSamples(
            cris.key,
            info,
            bt_viirs,
            bt_cris,
            ok,
            fg.sat_ecef_m[s5],
            fg.sbf_to_ecef[s5],
            fg.alpha_rad[s5],
            fg.beta_rad[s5],
            fg.velocity_ecef_m_s[s5],
            annuli,
        )
        for (bt_viirs, _, annuli), ok in zip(found, usable, strict=True)
    ]
    return replace(samples[0], rendered=samples[1] if len(samples) > 1 else None)


def _collocate_fors(
    pieces: swath.ViirsSwath,
    geo: CrisGeoGranule,
    fg: FovGeometry,
    valid: np.ndarray,
    fill: dict,
    cfg: AssessmentConfig,
    should_stop: StopCheck = None,
    smooth: bool = False,
) -> collocate.ConeSums:
    """The cone sums of every FOV of the granule (in one call of the parallel kernel), and of what each
    sees rendered when the pieces are (:attr:`monitor.collocation.sums.ConeSums.rendered`); smoothed over
    neighbouring perturbations when *smooth* (the M grid)."""
    if should_stop is not None and should_stop():
        raise StopRequested
    return collocate.cone_sums(
        pieces,
        fg.sat_ecef_m.reshape(-1, 3),
        fg.sbf_to_ecef.reshape(-1, 3, 3),
        fg.alpha_rad.ravel(),
        fg.beta_rad.ravel(),
        offsets_rad(cfg),
        KERNELS[cfg.kernel],
        fov_range_m=np.where(valid, geo.range_m, 1e6).ravel(),
        fov_cos_zen=np.cos(fill["zenith_rad"]).ravel(),
        smooth=smooth,
    )


def _per_fov(
    cones: collocate.ConeSums, fg: FovGeometry, cfg: AssessmentConfig, band: BandModel
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """VIIRS BT (nscan, 30, 9, m, m) of every perturbed cone, the worst coverage per FOV (of the outermost
    disc), and with the footprint kernel the radiance per annulus (nscan, 30, 9, K, m, m), else None."""
    m = len(offsets_rad(cfg))
    shape = fg.alpha_rad.shape
    cone = KERNELS[cfg.kernel].index(FOV_HALF_ANGLE_RAD)
    bt_viirs = band.bt_from_radiance(cones.mean(cone)).astype(np.float32).reshape(shape + (m, m))
    coverage = np.min(cones.coverage(), axis=(-2, -1)).reshape(shape)
    annuli = None
    if len(KERNELS[cfg.kernel]) > 1:
        annuli = cones.annulus_means().reshape(shape + (len(KERNELS[cfg.kernel]), m, m))
    return bt_viirs, coverage, annuli


def collocate_run(
    cris: list[GranuleFiles],
    viirs: dict[str, list[GranuleFiles]],
    viirs_all: list[GranuleFiles],
    satellite: str,
    cfg: AssessmentConfig,
    progress: Progress = None,
    should_stop: StopCheck = None,
    timings: Timings = None,
    lift_m_per_k: float = 0.0,
    variation: Variation = SERVICE,
    band: str = "I5",
) -> tuple[list[GranuleSamples], list[tuple[str, str]]]:
    """Collocate a time-ordered run of CrIS granules, and in the same pass their rendering at a lift.

    Parameters
    ----------
    cris : list of GranuleFiles
        The CrIS granules, in time order.
    viirs : dict of str to list of GranuleFiles
        Each CrIS granule's (by key) VIIRS granules.
    viirs_all : list of GranuleFiles
        Every VIIRS granule of the run.
    satellite : str
        The satellite's short name.
    cfg : AssessmentConfig
        The assessment's configuration.
    progress : callable, optional
        Called after each granule with its files.
    should_stop : callable, optional
        Polled before each granule; True ends the batch with :class:`StopRequested`.
    timings : dict, optional
        Collects seconds per stage (read, geometry, parallax, spectral, collocation, cost).
    lift_m_per_k : float, optional
        With a lift, the pixels also stand this many m per K above their GEO points, rendered as each CrIS
        FOV row sees them (:mod:`monitor.collocation.render`).
    variation : Variation, optional
        What a study varies: the renderer, the VIIRS granules as prepared (:mod:`monitor.assessment.seam`);
        the service's by default.
    band : str, optional
        The VIIRS band collocated: I5, or a long-wave M band (M15) with its M-band GEO in *viirs*.

    Returns
    -------
    samples : list of GranuleSamples
        The collocated granules.
    skipped : list of (str, str)
        The granules that failed, with their reasons.
    """
    model = band_model(satellite, band)
    spans = scan_spans(cris, viirs)
    cache = SwathCache(
        spans=spans,
        lift_m_per_k=lift_m_per_k,
        renderer=variation.renderer,
        piece=variation.piece,
        detectors=BANDS[band].grid.detectors,
        smoothed_cones=BANDS[band].grid.smoothed_cones,
    )
    samples, skipped = [], []
    reading: dict[str, float] = {}  # the read-ahead thread's seconds, added to *timings* at the end

    def _read_ahead(i: int) -> cf.Future[GranuleInputs]:
        """Read granule i's inputs (and compute its CrIS geometry) in the background while granule i - 1
        is computed (h5py, numpy and the compiled kernels release the interpreter to each other)."""
        prepared = set(cache.pieces) | ({v.key for v in viirs[cris[i - 1].key]} if i else set())
        return pool.submit(
            read_inputs, cris[i], viirs[cris[i].key], viirs_all, model, cfg, prepared, reading, cache.spans
        )

    with cf.ThreadPoolExecutor(1, thread_name_prefix="crisgeo-read") as pool:
        ahead = _read_ahead(0) if cris else None
        for i, g in enumerate(cris):
            current, ahead = ahead, None
            if should_stop is not None and should_stop():
                if current is not None:
                    current.cancel()
                skipped.append((g.key, "not assessed: stop requested"))
                continue
            if i + 1 < len(cris):
                ahead = _read_ahead(i + 1)
            try:
                samples.append(
                    collocate_granule(
                        g,
                        viirs[g.key],
                        cfg,
                        model,
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


class DayAssessment:
    """A day's assessment built batch by batch, so that a day can stop at the precision it needs.

    Each batch's CrIS granules are collocated once (as GEO places the pixels and, in the same pass, rendered,
    for the parallax) by :meth:`add`; the estimate over every granule so far is made whenever asked
    (:meth:`result`). Each granule's perturbed cones are kept on disk (:mod:`~monitor.assessment.spool`) until
    :meth:`close` (or the context's end): memory holds one granule's collocation and one FOR's estimate, not
    the day.

    Parameters
    ----------
    satellite : str
        The satellite's short name (``npp``, ``j01``, ``j02``).
    cfg : AssessmentConfig, optional
        The assessment's configuration; the defaults when None.
    workers : int, optional
        Threads of the compiled VIIRS preparation and collocation.
    variation : Variation, optional
        What a study varies (:mod:`monitor.assessment.seam`); the service's by default.
    band : str, optional
        The VIIRS band the geolocation is assessed in: I5 (the offsets), or M15 (the offsets read in a
        second band, on the M grid: :data:`monitor.core.bands.GRIDS`). A band of CrIS's long-wave band.
    """

    def __init__(
        self,
        satellite: str,
        cfg: AssessmentConfig | None = None,
        workers: int = 1,
        variation: Variation = SERVICE,
        band: str = "I5",
    ) -> None:
        if BANDS[band].cris_band != "LW":
            raise ValueError(f"band {band}: the geolocation is assessed in a band of CrIS's long-wave band")
        self.satellite, self.cfg, self.workers = satellite, cfg or AssessmentConfig(), workers
        self.variation, self.band = variation, band
        self.samples: list[GranuleSamples] = []
        self.skipped: list[tuple[str, str]] = []
        self._spool = Spool()

    def __enter__(self) -> DayAssessment:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Remove the day's spooled samples (the assessment is done with)."""
        self._spool.close()

    def add(
        self,
        case: CasePlan,
        progress: Progress = None,
        should_stop: StopCheck = None,
        timings: Timings = None,
    ) -> None:
        """Collocate every CrIS granule of a batch; a granule that fails is skipped with its reason.

        Granules go one after the other, each VIIRS granule prepared once per batch, on the constructor's
        *workers* threads.

        Parameters
        ----------
        case : CasePlan
            The batch's paired granules.
        progress : callable, optional
            Called after each granule with its files.
        should_stop : callable, optional
            Polled before each granule; True ends the batch with :class:`StopRequested`.
        timings : dict, optional
            Collects seconds per stage (read, geometry, parallax, spectral, collocation, cost).
        """
        cfg = self.cfg
        cris, viirs, viirs_all, uncovered = case.cris, case.viirs, case.viirs_all, []
        if self.band != "I5":  # the CrIS granules I5 pairs, each with the band's granules that cover it
            viirs, viirs_all = {g.key: case.cover(g, self.band) for g in cris}, case.bands.get(self.band, [])
            uncovered = [(g.key, f"no VIIRS {self.band} granule covers it") for g in cris if not viirs[g.key]]
            cris = [g for g in cris if viirs[g.key]]
        run = (cris, viirs, viirs_all, self.satellite, cfg)
        # with the parallax correction (the one place the setting is read), also the pixels at the probe's
        # height per K, rendered, in the same pass: monitor.estimation.parallax chooses the day's lift from
        # the two wherever every granule was rendered
        lift_m_per_k = self.variation.probe_m_per_k if cfg.parallax else 0.0
        with parallel_threads(self.workers):
            samples, skipped = collocate_run(
                *run, progress, should_stop, timings, lift_m_per_k, self.variation, self.band
            )
        self.skipped += list(case.skipped) + uncovered + skipped
        self.samples += [s.kept_in(self._spool) for s in samples]
        if should_stop is not None and should_stop():  # an interruption, not bad data: no cost stage either
            raise StopRequested

    def result(self, timings: Timings = None) -> AssessmentResult:
        """The estimate over every granule added, in time order.

        Parameters
        ----------
        timings : dict, optional
            Collects seconds per stage (read, geometry, parallax, spectral, collocation, cost).

        Returns
        -------
        AssessmentResult
            The day's result; an :class:`AssessmentError` naming the files with fewer usable FOVs in all than
            ``min_samples``.
        """
        cfg, skipped = self.cfg, self.skipped
        usable = sum(int(s.usable.sum()) for s in self.samples)
        if usable < cfg.min_samples:
            files = ", ".join(sorted({s.info.cris_geo for s in self.samples} | {str(k) for k, _ in skipped}))
            why = "; ".join(f"{k}: {r}" for k, r in skipped[:3])
            raise AssessmentError(
                f"too few usable FOVs to assess: {usable} (at least {cfg.min_samples}) in "
                f"{len(self.samples)} granule(s) [{files[:800]}]" + (f"; skipped: {why}" if why else "")
            )
        in_time = sorted(self.samples, key=lambda s: (s.info.start, s.key))
        with stage(timings, "cost"):
            return cost_and_offsets(
                in_time, cfg, skipped, self.satellite, self.variation, self._spool.parked, self.band
            )


def assess_plan(
    case: CasePlan,
    cfg: AssessmentConfig | None = None,
    progress: Progress = None,
    should_stop: StopCheck = None,
    timings: Timings = None,
    workers: int = 1,
) -> AssessmentResult:
    """Assess every CrIS granule of a plan in one batch (:class:`DayAssessment`).

    Parameters
    ----------
    case : CasePlan
        The paired granules.
    cfg : AssessmentConfig, optional
        The assessment's configuration; the defaults when None.
    progress : callable, optional
        Called after each granule with its files.
    should_stop : callable, optional
        Polled before each granule; True ends the batch with :class:`StopRequested`.
    timings : dict, optional
        Collects seconds per stage (read, geometry, parallax, spectral, collocation, cost).
    workers : int, optional
        Threads of the compiled kernels.

    Returns
    -------
    AssessmentResult
        The result; granules that fail are skipped with their reason, a stop request ends it with
        :class:`StopRequested`.
    """
    with DayAssessment(case.satellite, cfg, workers) as day:
        day.add(case, progress, should_stop, timings)
        return day.result(timings)


def in_second_band(
    case: CasePlan,
    result: AssessmentResult,
    cfg: AssessmentConfig,
    should_stop: StopCheck = None,
    timings: Timings = None,
) -> AssessmentResult:
    """The day's I5 *result* with its offsets read in M15 too, where ``assessment.bands`` lists M15.

    The CrIS granules of *case* are assessed again against their M15 granules (``case.bands``), as in I5
    (:class:`DayAssessment`, band M15), and paired with the I5 offsets
    (:func:`monitor.estimation.band_pair.with_second_band`).

    Parameters
    ----------
    case : CasePlan
        The day's assessed CrIS granules, with their M15 granules in ``bands``.
    result : AssessmentResult
        The day's I5 assessment.
    cfg : AssessmentConfig
        The assessment's configuration.
    should_stop : callable, optional
        Polled before each granule; True ends it with :class:`StopRequested`.
    timings : dict, optional
        Collects seconds per stage.

    Returns
    -------
    AssessmentResult
        *result* with the M15 offsets and the difference; unchanged where M15 is not configured; with a note
        where M15 leaves too little to assess.
    """
    if SECOND_BAND not in cfg.bands:
        return result
    with DayAssessment(case.satellite, cfg, cfg.workers, band=SECOND_BAND) as day:
        day.add(case, None, should_stop, timings)
        try:
            second = day.result(timings)
        except AssessmentError as exc:
            return replace(result, notes=[*result.notes, f"no offsets in {SECOND_BAND}: {exc}"])
    known = {s.item for s in result.skipped}
    notes = [f"{SECOND_BAND}: {s.item} skipped: {s.reason}" for s in second.skipped if s.item not in known]
    return replace(with_second_band(result, second), notes=[*result.notes, *notes])


def assess_paths(
    paths: Sequence[str | Path],
    cfg: AssessmentConfig | None = None,
    progress: Progress = None,
    workers: int = 1,
) -> AssessmentResult:
    """Find, pair and assess the granules under paths.

    Parameters
    ----------
    paths : sequence of str or Path
        Granule files or directories (CrIS SDR and GEO, VIIRS I5 SDR and image GEO).
    cfg : AssessmentConfig, optional
        The assessment's configuration; the defaults when None.
    progress : callable, optional
        Called after each granule with its files.
    workers : int, optional
        Threads of the compiled kernels.

    Returns
    -------
    AssessmentResult
        Per-FOR offsets (urad, km), sigmas, flags and the day's lift.
    """
    return assess_plan(plan(paths), cfg, progress, workers=workers)
