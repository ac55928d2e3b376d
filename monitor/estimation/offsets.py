"""A day's per-FOR offsets: each FOR's estimate (:mod:`monitor.estimation.estimate`) made a record.

Every :class:`~monitor.core.result.ForOffset` of the science is built here, by :func:`for_offset`, from its
parts: the turn and its sigma (urad, in the spacecraft body frame: alpha in-track, beta cross-track), its
displacement on the ground (km), the cost, the intercalibration, the fitted response, the FOV rows and the
day's parallax lift. Every sigma is final when it is put in: the jackknife's (counted as fewer granules by
the day's correlation of consecutive replicates), the estimator's floor and the spread the day's lift adds,
in quadrature, before the km sigmas are derived from them and before the uncertainty flag is judged.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR, URAD
from monitor.core.result import (
    FLAG_FEW_SAMPLES,
    FLAG_GAIN_UNDETERMINED,
    FLAG_TOP_HAT,
    FLAG_UNCERTAIN,
    DifferenceBin,
    ForOffset,
)
from monitor.core.vocabulary import Kernel
from monitor.estimation import jackknife
from monitor.estimation.estimate import ForEstimate, ForSamples, estimate
from monitor.estimation.intercal import NO_FIT, Intercalibration, difference_bins, reach_steps


@dataclass(frozen=True)
class Pair:
    """A FOR's two angles in the spacecraft body frame (alpha in-track, beta cross-track) with their sigmas,
    urad: the offsets, or the FOV rows ahead minus behind."""

    alpha_urad: float = np.nan
    beta_urad: float = np.nan
    sigma_alpha_urad: float = np.nan
    sigma_beta_urad: float = np.nan


@dataclass(frozen=True)
class Ground:
    """A FOR's offsets on the ground, in-track and cross-track, with their sigmas, km."""

    in_track_km: float = np.nan
    cross_track_km: float = np.nan
    sigma_in_track_km: float = np.nan
    sigma_cross_track_km: float = np.nan


@dataclass(frozen=True)
class Widths:
    """The full widths of a FOR's fitted response at 50 % and at 10 % of its peak, with their sigmas, urad."""

    at_50_urad: float = np.nan
    sigma_at_50_urad: float = np.nan
    at_10_urad: float = np.nan
    sigma_at_10_urad: float = np.nan


def floor_urad(
    cfg: AssessmentConfig, used: Kernel, cone_error_urad: tuple[float, float]
) -> tuple[float, float]:
    """What the estimator itself leaves beside the jackknife's scatter, added in quadrature.

    Parameters
    ----------
    cfg : AssessmentConfig
        The configuration: ``sigma_floor_urad`` and the kernel configured.
    used : Kernel
        The kernel the FOR's estimate used.
    cone_error_urad : tuple of float
        The day's own measure of the cone's error, in-track and cross-track, urad: the RMS of cone minus
        footprint over the FORs that fitted a response (0 where none did).

    Returns
    -------
    tuple of float
        In-track and cross-track, urad: ``sigma_floor_urad`` where configured; else nothing where the kernel
        used is the configured one, and *cone_error_urad* for a cone's estimate where the footprint is
        configured.
    """
    if cfg.sigma_floor_urad is not None:
        return cfg.sigma_floor_urad, cfg.sigma_floor_urad
    return (0.0, 0.0) if used == cfg.kernel else cone_error_urad


@dataclass(frozen=True)
class DayLift:
    """The day's parallax lift as the FORs' records carry it (:mod:`monitor.estimation.parallax`): the lift
    a VIIRS pixel got per K colder than its clear-sky neighbourhood (m/K; NaN: not collocated lifted), the
    height each FOR's cold scenes were put at (km), and the sigma the lift's own uncertainty adds to each
    FOR's offsets and FOV rows (urad). Arrays of shape (N_FOR,)."""

    m_per_k: float
    height_km: np.ndarray
    sigma_alpha_urad: np.ndarray
    sigma_beta_urad: np.ndarray
    sigma_rows_alpha_urad: np.ndarray
    sigma_rows_beta_urad: np.ndarray


NO_LIFT = DayLift(np.nan, np.full(N_FOR, np.nan), *np.zeros((4, N_FOR)))


@dataclass(frozen=True)
class OffsetReplicates:
    """One FOR's jackknife replicates of its offsets: the first and last granule each leaves out (indices
    into the day's granules in time order, shape (G, 2)), its offsets (urad, alpha and beta, shape (G, 2)),
    and the factor the day's correlation of consecutive granules makes of its sigmas."""

    granules: np.ndarray
    urad: np.ndarray
    factor: float


@dataclass(frozen=True)
class DayEstimate:
    """The 30 FORs' offsets of a day, their cost surfaces (30, m, m; NaN where none), the CrIS - VIIRS
    difference in BT bins pooled over the FORs refined (the paper's Figure 15) and the correlation of
    consecutive granules the sigmas count."""

    fors: list[ForOffset]
    cost_cube_k: np.ndarray
    difference_bins: list[DifferenceBin]
    correlation: float = 0.0  # of consecutive granules' replicates (jackknife.adjacent_correlation)
    replicates: list[OffsetReplicates | None] = field(default_factory=list)  # per FOR, where it has them


KmOf = Callable[[int, float, float], tuple[float, float, np.ndarray]]


def for_offset(
    for_index: int,
    n_samples: int,
    turn: Pair,
    ground: Ground,
    cost_min_k: float,
    cost_zero_k: float,
    cal: Intercalibration,
    widths: Widths,
    rows: Pair,
    lift_m_per_k: float,
    lift_height_km: float,
    flags: Iterable[str],
) -> ForOffset:
    """The record of one FOR from its parts; non-finite parts stay NaN (nothing was measured there).

    Parameters
    ----------
    for_index : int
        The FOR, 1..30.
    n_samples : int
        The FOVs in its cost.
    turn : Pair
        The offsets (d_alpha, d_beta) and their final sigmas, urad, spacecraft body frame.
    ground : Ground
        The in-track and cross-track errors on the ground and their sigmas, km.
    cost_min_k, cost_zero_k : float
        The cost at the minimum and at no turn, K.
    cal : Intercalibration
        The CrIS-VIIRS intercalibration at the optimum.
    widths : Widths
        The fitted response's full widths and their sigmas, urad.
    rows : Pair
        The FOV rows ahead minus behind, alpha and beta, and their sigmas, urad.
    lift_m_per_k : float
        The day's lift, m/K.
    lift_height_km : float
        The height the lift gives the FOR's cold scenes, km.
    flags : iterable of str
        The FOR's flags.

    Returns
    -------
    ForOffset
        The record.
    """
    return ForOffset(
        for_index=for_index,
        d_alpha_urad=float(turn.alpha_urad),
        d_beta_urad=float(turn.beta_urad),
        sigma_alpha_urad=float(turn.sigma_alpha_urad),
        sigma_beta_urad=float(turn.sigma_beta_urad),
        in_track_km=float(ground.in_track_km),
        cross_track_km=float(ground.cross_track_km),
        total_km=float(np.hypot(ground.in_track_km, ground.cross_track_km)),
        sigma_in_track_km=float(ground.sigma_in_track_km),
        sigma_cross_track_km=float(ground.sigma_cross_track_km),
        n_samples=int(n_samples),
        cost_min_k=float(cost_min_k),
        cost_zero_k=float(cost_zero_k),
        bias_k=cal.bias_k,
        sigma_bias_k=cal.sigma_bias_k,
        gain_pct=cal.gain_pct,
        sigma_gain_pct=cal.sigma_gain_pct,
        curvature_k=cal.curvature_k,
        sigma_curvature_k=cal.sigma_curvature_k,
        response_width_50_urad=float(widths.at_50_urad),
        sigma_response_width_50_urad=float(widths.sigma_at_50_urad),
        response_width_10_urad=float(widths.at_10_urad),
        sigma_response_width_10_urad=float(widths.sigma_at_10_urad),
        fov_rows_alpha_urad=float(rows.alpha_urad),
        fov_rows_beta_urad=float(rows.beta_urad),
        sigma_fov_rows_alpha_urad=float(rows.sigma_alpha_urad),
        sigma_fov_rows_beta_urad=float(rows.sigma_beta_urad),
        parallax_m_per_k=float(lift_m_per_k),
        parallax_height_km=float(lift_height_km),
        flags=tuple(sorted(set(flags))),
    )


def _cone_error_urad(estimates: list[ForEstimate | None], step_urad: float) -> tuple[float, float]:
    """The RMS over the FORs that fitted a response of the cone's optimum minus the footprint's (urad)."""
    cone = np.array([(e.cone[0] - e.x, e.cone[1] - e.y) for e in estimates if e is not None and e.footprint])
    if not len(cone):
        return 0.0, 0.0
    return (
        float(np.sqrt(np.mean(cone[:, 0] ** 2))) * step_urad,
        float(np.sqrt(np.mean(cone[:, 1] ** 2))) * step_urad,
    )


def day_offsets(
    per_for: Sequence[ForSamples],
    cfg: AssessmentConfig,
    step_urad: float,
    km: KmOf | None = None,
    follows: np.ndarray | None = None,
    lift: DayLift = NO_LIFT,
) -> DayEstimate:
    """Every FOR's estimate of a day as a :class:`~monitor.core.result.ForOffset`.

    Angles in urad with the jackknife sigma, the floor and the lift's spread in quadrature, flags and the
    intercalibration.

    Parameters
    ----------
    per_for : sequence of ForSamples
        Each FOR's samples; may build them when indexed (a long day's are read from disk): each is taken once,
        and dropped once estimated.
    cfg : AssessmentConfig
        The assessment's configuration.
    step_urad : float
        The perturbation step, urad.
    km : callable, optional
        Given a FOR (0-based) and a turn (rad), the mean in-track and cross-track km of it and its Jacobian
        (km/rad); the km are NaN without.
    follows : numpy.ndarray, optional
        Per granule, whether it directly follows the one before: such granules count as fewer by the day's
        correlation of their replicates (:mod:`monitor.estimation.jackknife`).
    lift : DayLift, optional
        The day's lift and the spread it adds to each FOR, in quadrature.

    Returns
    -------
    DayEstimate
        The 30 records, their cost surfaces, the CrIS - VIIRS difference in BT bins and the correlation the
        sigmas count.
    """
    reach = reach_steps(step_urad * URAD)

    def _one(k: int) -> tuple[ForEstimate | None, np.ndarray]:
        """FOR k's estimate (None with fewer than 3 samples) and its samples' CrIS BT."""
        s = per_for[k]
        return (
            estimate(s, cfg.cost, cfg.flat_contrast, cfg.uncertainty, reach) if len(s) >= 3 else None
        ), s.cris_k

    # the FORs are independent: estimated on the assessment's threads (numpy and the compiled BT inversion
    # leave the interpreter's lock), each the same numbers as alone
    with ThreadPoolExecutor(max_workers=max(1, cfg.workers), thread_name_prefix="estimate") as pool:
        estimates, cris = (list(x) for x in zip(*pool.map(_one, range(len(per_for))), strict=True))
    m = next((e.cost.shape[0] for e in estimates if e is not None), 2 * cfg.half_steps + 1)
    cube = np.full((len(per_for), m, m), np.nan)
    series = [
        (e.granules, e.replicates)
        for e in estimates
        if e is not None and e.granules is not None and e.replicates is not None
    ]
    correlation = jackknife.adjacent_correlation(series, follows) if follows is not None else 0.0
    cone_error_urad = _cone_error_urad(estimates, step_urad)
    fors = []
    replicates: list[OffsetReplicates | None] = [None] * len(cris)
    pooled: list[tuple] = []  # (CrIS BT, VIIRS BT) at the optimum of each refined FOR
    for k, cris_k in enumerate(cris):
        n = len(cris_k)
        flags = [FLAG_FEW_SAMPLES] if n < max(cfg.min_samples, 3) else []
        x = y = sig_a = sig_b = np.nan
        g = np.full((m, m), np.nan)
        cal = NO_FIT
        widths = Widths()
        rows = Pair()  # ahead minus behind
        best = estimates[k]
        if best is not None:
            # every sigma of the FOR from the same replicates: the same count of independent granules
            factor = (
                1.0
                if best.granules is None
                else jackknife.correlation_factor(len(best.granules), correlation)
            )
            if best.footprint is not None:
                fp = best.footprint
                widths = Widths(
                    fp.width_50_rad / URAD,
                    factor * (fp.sigma_width_50_rad / URAD),
                    fp.width_10_rad / URAD,
                    factor * (fp.sigma_width_10_rad / URAD),
                )
            g, x, y, cal = best.cost, best.x, best.y, best.intercalibration.sigmas_scaled(factor)
            (row_a, row_b), (row_sa, row_sb) = best.rows, best.rows_sigma
            rows = Pair(
                row_a * step_urad,
                row_b * step_urad,
                float(np.hypot(factor * row_sa * step_urad, lift.sigma_rows_alpha_urad[k])),
                float(np.hypot(factor * row_sb * step_urad, lift.sigma_rows_beta_urad[k])),
            )
            if cal.gain_undetermined:
                flags.append(FLAG_GAIN_UNDETERMINED)
            cube[k] = g
            flags += best.flags
            if best.refined:
                pooled.append((cris_k, best.d_opt + cris_k))
            # the kernel used: the footprint where a response was fitted, else the cone (too few FOVs, cone
            # means, no refined minimum), said in the flags, its floor the cone's
            used = Kernel.FOOTPRINT if best.footprint is not None else Kernel.TOP_HAT
            if used != cfg.kernel:
                flags.append(FLAG_TOP_HAT)
            floor = floor_urad(cfg, used, cone_error_urad)
            sig_a = float(
                np.hypot(np.hypot(factor * best.sigma[0] * step_urad, floor[0]), lift.sigma_alpha_urad[k])
            )
            sig_b = float(
                np.hypot(np.hypot(factor * best.sigma[1] * step_urad, floor[1]), lift.sigma_beta_urad[k])
            )
            if max(sig_a, sig_b) > cfg.max_sigma_urad:
                flags.append(FLAG_UNCERTAIN)
            if best.granules is not None and best.replicates is not None:
                replicates[k] = OffsetReplicates(best.granules, best.replicates * step_urad, factor)
        d_alpha, d_beta = x * step_urad, y * step_urad
        ground = Ground()
        if km is not None:
            it, ct, jac = km(k, d_alpha * URAD, d_beta * URAD)
            s_it = s_ct = np.nan
            if np.isfinite(sig_a):
                s_it = float(np.hypot(jac[0, 0] * sig_a, jac[0, 1] * sig_b) * URAD)
                s_ct = float(np.hypot(jac[1, 0] * sig_a, jac[1, 1] * sig_b) * URAD)
            ground = Ground(it, ct, s_it, s_ct)
        cost_min_k, cost_zero_k = (
            (float(np.nanmin(g)), float(g[m // 2, m // 2])) if n >= 3 else (np.nan, np.nan)
        )
        fors.append(
            for_offset(
                k + 1,
                n,
                Pair(d_alpha, d_beta, sig_a, sig_b),
                ground,
                cost_min_k,
                cost_zero_k,
                cal,
                widths,
                rows,
                lift.m_per_k,
                lift.height_km[k],
                flags,
            )
        )
    bins = difference_bins(*(np.concatenate(v) for v in zip(*pooled, strict=True))) if pooled else []
    return DayEstimate(fors, cube, bins, correlation, replicates)
