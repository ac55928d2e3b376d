"""The day's estimate from its collocated granules: per FOR the samples over the granules, the day's lift
chosen by the cost (:mod:`monitor.estimation.parallax`), the offsets and their sigmas
(:mod:`monitor.estimation.offsets`), and the offsets on the ground in km (Wang et al. 2017, section 2.4).

:class:`GranuleSamples` is what :mod:`monitor.assessment.assess` collocates of one CrIS granule.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from monitor.assessment.inputs import KERNELS, offsets_rad
from monitor.assessment.seam import SERVICE, Variation
from monitor.assessment.spool import OnDisk, Spool
from monitor.config.assessment import AssessmentConfig
from monitor.core.result import AssessmentResult, ForReplicates, GranuleInfo, Skipped
from monitor.estimation.day_estimate import DaySamples, Parked, estimate_day, in_memory
from monitor.estimation.estimate import ForSamples
from monitor.estimation.jackknife import follows_in_time, uncertainty_note
from monitor.estimation.offsets import OffsetReplicates
from monitor.geometry.ground import offset_km
from monitor.instrument.spectral import BandModel, band_model


@dataclass
class GranuleSamples:
    """Collocated samples of one CrIS granule: per FOV the VIIRS BT of every perturbed cone."""

    key: str
    info: GranuleInfo
    bt_viirs_k: np.ndarray | OnDisk  # (nscan, 30, 9, m, m) through the top-hat cone
    bt_cris_k: np.ndarray  # (nscan, 30, 9)
    usable: np.ndarray  # (nscan, 30, 9)
    sat_m: np.ndarray  # FOV-5 geometry per (nscan, 30) for the km conversion
    sbf_to_ecef: np.ndarray
    alpha_rad: np.ndarray
    beta_rad: np.ndarray
    velocity_m_s: np.ndarray
    annuli_rad: np.ndarray | OnDisk | None = None  # (nscan, 30, 9, K, m, m) radiance per annulus (footprint)
    # the same granule with the VIIRS pixels standing at a height, rendered as each FOV row sees them
    rendered: GranuleSamples | None = None

    def kept_in(self, spool: Spool) -> GranuleSamples:
        """These samples with their perturbed cones' arrays kept on disk.

        Parameters
        ----------
        spool : Spool
            Where to keep them (:mod:`monitor.assessment.spool`).

        Returns
        -------
        GranuleSamples
            The same samples, read back from disk when indexed.
        """
        cones = self.bt_viirs_k if isinstance(self.bt_viirs_k, OnDisk) else spool.keep(self.bt_viirs_k)
        annuli = self.annuli_rad
        if isinstance(annuli, np.ndarray):
            annuli = spool.keep(annuli)
        rendered = None if self.rendered is None else self.rendered.kept_in(spool)
        return replace(self, bt_viirs_k=cones, annuli_rad=annuli, rendered=rendered)


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
    samples: list[GranuleSamples], k: int, cfg: AssessmentConfig, band: BandModel | None = None
) -> ForSamples:
    """The estimator's input for one FOR: every usable FOV of it over the granules.

    Parameters
    ----------
    samples : list of GranuleSamples
        The collocated granules, in time order.
    k : int
        The FOR, 0-based.
    cfg : AssessmentConfig
        The assessment's configuration.
    band : BandModel, optional
        The collocated band, for the footprint kernel's annuli.

    Returns
    -------
    ForSamples
        The FOR's samples.
    """
    m = len(offsets_rad(cfg))
    d, granule, scan, fov, annuli = [], [], [], [], []
    for g_i, s in enumerate(samples):
        use = s.usable[:, k]  # (nscan, 9)
        d.append((s.bt_viirs_k[:, k][use] - s.bt_cris_k[:, k][use][:, None, None]).astype(np.float64))
        scans, fovs = np.nonzero(use)  # the scan and FOV of each sample
        granule.append(np.full(scans.size, g_i))
        scan.append(scans)
        fov.append(fovs)
        if s.annuli_rad is not None:
            annuli.append(s.annuli_rad[:, k][use])
    footprint = len(KERNELS[cfg.kernel]) > 1
    return ForSamples(
        np.concatenate(d) if d else np.empty((0, m, m)),
        _cris_k(samples, k),
        np.concatenate(granule) if granule else np.empty(0, int),
        np.concatenate(scan) if scan else np.empty(0, int),
        np.concatenate(annuli) if footprint and annuli else None,
        KERNELS[cfg.kernel] if footprint else (),
        band,
        np.concatenate(fov) if fov else np.empty(0, int),
    )


def cost_and_offsets(
    samples: list[GranuleSamples],
    cfg: AssessmentConfig,
    skipped: Sequence[tuple[str, str]] | None = None,
    satellite: str = "",
    variation: Variation = SERVICE,
    keep: Callable[[ForSamples], Parked] = in_memory,
    band: str = "I5",
) -> AssessmentResult:
    """The cost cube, per-FOR minimum, jackknife uncertainty and km offsets of collocated *samples*.

    When every granule was also collocated with the VIIRS pixels standing at the probe's height
    (:attr:`GranuleSamples.rendered`: rendered as each FOV row sees them, :mod:`monitor.collocation.render`;
    :class:`~monitor.assessment.DayAssessment` does so with the parallax correction), the day's lift is
    chosen by the cost (:mod:`monitor.estimation.parallax`) and the offsets are estimated at it.

    Parameters
    ----------
    samples : list of GranuleSamples
        The collocated granules, in time order.
    cfg : AssessmentConfig
        The assessment's configuration (grid, kernel, cost, parallax, uncertainty).
    skipped : sequence of (str, str), optional
        Granules left out and why, carried into the result.
    satellite : str, optional
        The satellite's short name (``j01``); by default the first granule's platform.
    variation : Variation, optional
        What a study varies: the probe's lift the rendered collocation was made at, how a FOR's two
        collocations are combined (:mod:`monitor.assessment.seam`); the service's by default.
    keep : callable, optional
        Where each FOR's built samples wait while the day's lift is sought (the day's spool,
        :meth:`Spool.parked <monitor.assessment.spool.Spool.parked>`); in memory by default.
    band : str, optional
        The VIIRS band the samples were collocated in (I5, or M15).

    Returns
    -------
    AssessmentResult
        Per-FOR offsets (urad, km), sigmas, flags and the day's lift.
    """
    model = band_model(satellite or samples[0].info.cris_meta["platform"], band) if samples else None
    rendered = bool(samples) and all(s.rendered is not None for s in samples)
    at_geo, at_probe = paired(samples) if rendered else (samples, None)
    day = estimate_day(
        DaySamples(
            lambda k: for_samples(at_geo, k, cfg, model),
            None if at_probe is None else lambda k: for_samples(at_probe, k, cfg, model),
            lambda k, d_alpha_rad, d_beta_rad: _ground_km(samples, k, d_alpha_rad, d_beta_rad),
            follows_in_time([_seconds(s.info.start) for s in samples]),
            variation.probe_m_per_k,
            variation.blend,
            keep,
        ),
        cfg,
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
        notes=[uncertainty_note(len(samples), day.correlation)],
        replicates=[None if r is None else _by_granule(r, samples) for r in day.replicates],
    )


def _by_granule(r: OffsetReplicates, samples: list[GranuleSamples]) -> ForReplicates:
    """A FOR's replicates with the granules they leave out named by granule id."""
    ids = [s.info.granule_id for s in samples]
    groups = tuple((ids[int(a)], ids[int(b)]) for a, b in r.granules)
    return ForReplicates(groups, r.urad[:, 0].copy(), r.urad[:, 1].copy(), r.factor)


def _seconds(iso: str) -> float:
    """Seconds since the epoch of an ISO time (NaN where there is none: then no granule follows another)."""
    try:
        return dt.datetime.fromisoformat(iso).timestamp()
    except ValueError:
        return np.nan


def paired(samples: list[GranuleSamples]) -> tuple[list[GranuleSamples], list[GranuleSamples]]:
    """The granules of both collocations, at the GEO points and rendered, with the FOVs usable in both.

    Parameters
    ----------
    samples : list of GranuleSamples
        Granules collocated with their rendering (:attr:`GranuleSamples.rendered`).

    Returns
    -------
    at_geo, rendered : list of GranuleSamples
        The two collocations; a ValueError if a granule was not rendered.
    """
    rendered = [s.rendered for s in samples if s.rendered is not None]
    if len(rendered) != len(samples):
        raise ValueError("paired: a granule was not collocated rendered")
    both = [s.usable & r.usable for s, r in zip(samples, rendered, strict=True)]
    return (
        [replace(s, usable=u, rendered=None) for s, u in zip(samples, both, strict=True)],
        [replace(r, usable=u) for r, u in zip(rendered, both, strict=True)],
    )


def _cris_k(samples: list[GranuleSamples], k: int) -> np.ndarray:
    """The CrIS BT (K) of FOR k's usable FOVs over the granules, in order (the samples' cris_k)."""
    return np.concatenate([s.bt_cris_k[:, k][s.usable[:, k]] for s in samples] or [np.empty(0)]).astype(
        np.float64
    )
