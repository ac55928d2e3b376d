"""A day's estimate in one call: the day's samples in, the day's lift and every FOR's record out.

The assessment hands the estimation a :class:`DaySamples` once: how to build each FOR's samples (at the VIIRS
GEO points and, where the day was also collocated with the pixels rendered at the probe's lift, rendered),
the turn's displacement on the ground, and which granules follow one another. :func:`estimate_day` then
chooses the day's lift from the cost where there is a rendering (:mod:`monitor.estimation.parallax`) and
estimates every FOR at it (:mod:`monitor.estimation.offsets`; Wang et al. 2017, sections 2.3-2.4).

Each FOR's samples are built once. The lift needs every FOR's samples before any FOR can be estimated at it,
so the first pass puts each FOR's two collocations aside through :attr:`DaySamples.keep` (the assessment's
spool: on disk, one FOR in memory at a time) and the second reads them back and blends them at the day's
lift.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np

from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR
from monitor.estimation import parallax
from monitor.estimation.estimate import ForSamples
from monitor.estimation.offsets import NO_LIFT, DayEstimate, DayLift, KmOf, day_offsets

BuildFor = Callable[[int], ForSamples]  # FOR k's (0-based) samples over the day
Parked = Callable[[], ForSamples]  # a FOR's samples put aside, handed back when called


def in_memory(s: ForSamples) -> Parked:
    """*s* put aside in memory for the second pass (a short day's way).

    Parameters
    ----------
    s : ForSamples
        A FOR's samples.

    Returns
    -------
    callable
        Hands *s* back.
    """
    return lambda: s


@dataclass(frozen=True)
class DaySamples:
    """A day as the assessment hands it to the estimation.

    Attributes
    ----------
    at_geo : callable
        FOR k's (0-based) samples with the VIIRS pixels at their GEO points.
    rendered : callable or None
        FOR k's samples with the pixels rendered at :attr:`probe_m_per_k` as each FOV row sees them, the same
        FOVs as :attr:`at_geo`'s; None where the day was not rendered (no lift is then sought).
    km : callable
        Given a FOR (0-based) and a turn (rad), the mean in-track and cross-track km of it and its Jacobian.
    follows : numpy.ndarray
        Per granule, whether it directly follows the one before (the jackknife's correlation).
    probe_m_per_k : float
        The lift of the rendered collocation, m per K of I5 BT below the clear sky.
    blend : Blend
        How a FOR's two collocations combine at a fraction of the probe's lift
        (:func:`monitor.estimation.parallax.blend`; a study's through :mod:`monitor.assessment.seam`).
    keep : callable
        Puts a FOR's built samples aside for the second pass and returns what hands them back (by default
        they wait in memory).
    """

    at_geo: BuildFor
    rendered: BuildFor | None
    km: KmOf
    follows: np.ndarray
    probe_m_per_k: float
    blend: parallax.Blend = parallax.blend
    keep: Callable[[ForSamples], Parked] = in_memory


def estimate_day(day: DaySamples, cfg: AssessmentConfig) -> DayEstimate:
    """Every FOR's estimate of a day at the day's lift (none where the day was not rendered, or the cost
    declines it).

    Parameters
    ----------
    day : DaySamples
        The day's samples.
    cfg : AssessmentConfig
        The assessment's configuration (grid, kernel, cost, uncertainty).

    Returns
    -------
    DayEstimate
        The 30 records, their cost surfaces, the CrIS - VIIRS difference in BT bins and the correlation the
        sigmas count.
    """
    if day.rendered is None:
        return day_offsets(PerFor(day.at_geo), cfg, cfg.step_urad, day.km, day.follows, NO_LIFT)
    kept, cones0, cones1, cris = [], [], [], []
    for k in range(N_FOR):
        s0, s1 = day.at_geo(k), day.rendered(k)
        c0, c1 = parallax.matched_cone(s0, s1, cfg.cost)
        cones0.append(c0)
        cones1.append(c1)
        cris.append(s0.cris_k)
        kept.append((day.keep(s0), day.keep(s1)))
    f, sigma_f = parallax.day_lift(cones0, cones1, cfg.cost, day.probe_m_per_k)
    spread = np.zeros((N_FOR, 4))  # the sigma (steps) the day's lift adds: FOR alpha, beta; rows alpha, beta
    if cfg.uncertainty and np.isfinite(sigma_f):
        spread = np.array(
            [
                np.abs(parallax.sensitivity(a, b, f, cfg.cost)) * sigma_f if len(a) >= 3 else np.zeros(4)
                for a, b in zip(cones0, cones1, strict=True)
            ]
        )
    m_per_k = f * day.probe_m_per_k
    # parallax.sensitivity's order: FOR alpha, beta; rows alpha, beta
    sigma_alpha, sigma_beta, sigma_rows_alpha, sigma_rows_beta = (np.nan_to_num(spread) * cfg.step_urad).T
    lift = DayLift(
        m_per_k,
        np.array([cold_height_km(c, m_per_k) for c in cris]),
        sigma_alpha,
        sigma_beta,
        sigma_rows_alpha,
        sigma_rows_beta,
    )
    per_for = PerFor(lambda k: day.blend(kept[k][0](), kept[k][1](), f))
    return day_offsets(per_for, cfg, cfg.step_urad, day.km, day.follows, lift)


def cold_height_km(cris_k: np.ndarray, m_per_k: float) -> float:
    """The height the correction puts a FOR's cold scenes at: *m_per_k* times its CrIS BT's 95th minus 5th
    percentile.

    Parameters
    ----------
    cris_k : numpy.ndarray
        The FOR's CrIS BT over the day, K.
    m_per_k : float
        The day's lift, m per K.

    Returns
    -------
    float
        km; NaN with fewer than 3 samples or no lift.
    """
    if len(cris_k) < 3 or not np.isfinite(m_per_k):
        return np.nan
    return float(m_per_k * np.subtract(*np.percentile(cris_k, [95, 5])) / 1000.0)


class PerFor(Sequence[ForSamples]):
    """The 30 FORs' samples, each built when indexed: one FOR of a long day is in memory at a time, not
    the day (:func:`~monitor.estimation.offsets.day_offsets` takes each once).

    Parameters
    ----------
    build : callable
        Builds FOR k's (0-based) samples.
    """

    def __init__(self, build: BuildFor) -> None:
        self._build = build

    def __len__(self) -> int:
        return N_FOR

    @overload
    def __getitem__(self, k: int) -> ForSamples: ...

    @overload
    def __getitem__(self, k: slice) -> list[ForSamples]: ...

    def __getitem__(self, k: int | slice) -> ForSamples | list[ForSamples]:
        if isinstance(k, slice):
            return [self._build(i) for i in range(N_FOR)[k]]
        if not -N_FOR <= k < N_FOR:
            raise IndexError(k)
        return self._build(k % N_FOR)
