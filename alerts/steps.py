"""Steps in a daily per-FOR series, tested with the sigmas the assessment reports.

**The model.** On assessed day t the value of FOR k in direction c (in-track alpha and cross-track beta, in
urad; or the CrIS-VIIRS bias, in K) is its level plus an error

    e[t, k, c] = lambda_c * s[t, k, c] * (sqrt(rho_c) g[t, c] + sqrt(1 - rho_c) h[t, k, c]),

s the reported sigma, lambda_c the scale of the real scatter to the reported one, rho_c the share of the
error variance that the FORs of one day have in common (their scenes are shared), g and h unit AR(1)
series over calendar days with lag-one correlation phi. The three are fitted from the history, never
assumed (:func:`alerts.noise.fit_noise`): from first differences of consecutive days, so a step costs one
outlier, with medians, so outliers cost nothing. lambda checks the reported sigmas against the day-to-day
scatter: sigmas too small make lambda > 1, so such days cannot page; honest ones give lambda ~ 1.

**The test.** A step at day tau seen on day T compares, per FOR and direction, the inverse-variance mean
of the days [tau, T] with that of the baseline before tau (at most ``baseline_days``, after the last
accepted step): D_k with variance V_k = lambda^2 u^T Phi u (u the contrast times the sigmas, Phi the
AR(1) correlation of the days). For a group G of FORs (all 30, the three tens, every 3 adjacent, each
alone) the step common to G is its generalised least-squares estimate under the exchangeable correlation
rho of the D_k (:func:`alerts.noise.pooled`): the FORs outside G then measure the shared part of the error, so
a step of a few FORs is seen through it. z = estimate / sigma.

**The thresholds** come from false-detection rates (:func:`threshold`): on each day the blind test tries
the splits T, T-1, T-2 (a step is found within three days) for every group and both directions; the
largest |z| of that family, simulated under the fitted rho and phi, exceeds the threshold on a fraction
``rate_per_year / 365`` of days (:data:`RATE_MARGIN` of it: the rate is a bound). At a known change
(calendar, metadata, fingerprint) the day that holds it is left out of both windows, and its family,
the first three days after it, exceeds its own threshold with probability ``rate_at_change`` (its
margin likewise). The simulation computes the z's as the rule does, with a noise
fitted from as many days as the rule had (:func:`_simulated_fits`): a fit from a few weeks misjudges
rho and lambda by several per cent, which at |z| ~ 4.5 multiplies the false detections, so a young
history is judged by a higher threshold.

**The replay.** The rule keeps no state: each evaluation replays the last ``2 * baseline_days`` days as the
daily evaluations saw them (:func:`detect`), accepting steps in time order; a step starts a new baseline.
A split is judged by the noise fitted on the days before the refit date (every four weeks, on fixed dates)
on or before its baseline: the fit depends on the split alone, so every evaluation decides it alike, once,
not anew each day under a fit that moved a little (each such look would be another chance of a false
detection).
Those whose split lies in the last ``baseline_days`` days are reported: an alert resolves once the new
level has held for the baseline's length. A slow drift has no split: it is not a step, and is found only
where it adds up to one within the baseline's length.
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from alerts.noise import (
    GROUPS,
    MEMBERS,
    MIN_HISTORY_DAYS,
    FitSource,
    FittedNoise,
    Noise,
    ar1_correlation,
    fit_noise,
    fitted_before,
    pooled,
    step_contrast,
)
from monitor.core.constants import N_FOR

NULL_DRAWS = 200_000  # simulated days per threshold: ~550 beyond it at 1/365
REFIT_DAYS = 28  # the noise is fitted anew every four weeks (detect)
REFIT_EPOCH = dt.date(2000, 1, 3).toordinal()  # a Monday: the refits' dates
# the thresholds are simulated for this share of the configured rates: the rates are bounds ("at most"),
# and the noise model (Gaussian, one AR(1) for the shared and the own error) is not the history itself
RATE_MARGIN = 0.8


@dataclass(frozen=True)
class StepRules:
    """What the detector is told: the false-detection rates (per satellite-year on unannounced days, per
    inert known change), the baseline's length (days), the fewest baseline days a test needs, the days
    after a split the blind test tries it (``discovery_days``), the days after a split its size is
    measured over, and the practical size (the series' unit) below which a step is recorded, not paged."""

    rate_per_year: float
    rate_at_change: float
    baseline_days: int
    min_baseline_days: int
    discovery_days: int
    size_days: int
    practical: float
    attribution_days: int


@dataclass(frozen=True)
class Step:
    """A step found: its *split* (the first day at the new level; for a known change, the change's day),
    the known change's index in the changes given (None: none within ``attribution_days``), the day it
    was first seen, the group and direction that found it with its *z* and pooled size (and sigma), and
    per FOR and direction its size and sigma (NaN where not measured); *paged* when its pooled size
    reaches the practical size."""

    split: dt.date
    change: int | None
    seen: dt.date
    group: str
    direction: int
    z: float
    pooled: float
    pooled_sigma: float
    size: np.ndarray  # (N_FOR, directions)
    sigma: np.ndarray
    paged: bool


def replay_reach(rules: StepRules) -> int:
    """The calendar days before the last one that :func:`detect` reads: the replay's ``2 * baseline_days``,
    the discovery days before its first split, and a baseline (moved to a known change up to
    ``attribution_days`` earlier) before those. Older days enter only through the noise fits.

    Parameters
    ----------
    rules : StepRules
        The detector's parameters.

    Returns
    -------
    int
        Days.
    """
    return 3 * rules.baseline_days + rules.discovery_days + rules.attribution_days


# the fits' lengths (days) thresholds are simulated for
FIT_DAYS = (MIN_HISTORY_DAYS + 1, 30, 40, 50, 60, 75, 90, 105, 120, 140, 160, 180, 210, 240, 270, 300, 365)
FIT_DRAWS = 50  # simulated fits per threshold: the fitted noise's own error


def fit_days_bucket(n: int) -> int:
    """The length of :data:`FIT_DAYS` a fit of *n* days is judged as: the next shorter one (its noise is
    known no better than that), a year for longer fits.

    Parameters
    ----------
    n : int
        Days fitted.

    Returns
    -------
    int
        The bucket's length, days.
    """
    return max([b for b in FIT_DAYS if b <= n], default=FIT_DAYS[0])


def _simulated_fits(shared: float, lag1: float, fit_days: int, directions: int) -> list[Noise]:
    """:data:`FIT_DRAWS` noises :func:`alerts.noise.fit_noise` fits on *fit_days* days in a row of unit sigmas
    whose
    true noise is scale 1, *shared* and *lag1* (a fixed seed): the spread of what the rule would believe."""
    rng = np.random.default_rng(20261128)
    out = []
    for _ in range(FIT_DRAWS):
        g = rng.standard_normal((fit_days, 1, directions))
        h = rng.standard_normal((fit_days, N_FOR, directions))
        e = math.sqrt(shared) * g + math.sqrt(1.0 - shared) * h
        for t in range(1, fit_days):
            e[t] = lag1 * e[t - 1] + math.sqrt(1.0 - lag1**2) * e[t]
        fit = fit_noise(np.arange(fit_days), e, np.ones_like(e))
        assert fit is not None  # fit_days > MIN_HISTORY_DAYS days in a row
        out.append(fit)
    return out


@lru_cache(maxsize=1024)
def threshold(
    probability: float,
    shared: float,
    lag1: float,
    baseline: int,
    discovery: int,
    known: bool,
    directions: int,
    fit_days: int,
) -> float:
    """The |z| the family of one evaluation day exceeds with *probability* under the null: for the blind
    test the splits T - discovery + 1 .. T seen on day T; for a known change the first *discovery* days
    after it (the change's day left out). Simulated (:data:`NULL_DRAWS` days, a fixed seed) for every group
    and direction, the FORs correlated by *shared*, the days by *lag1*, uniform sigmas.

    The z's are those the rule computes: with a noise fitted on *fit_days* days, not the true one. The
    draws are split among :data:`FIT_DRAWS` fits of simulated histories (:func:`_simulated_fits`); each
    scales a split's contrast by its fit's sigma (lambda_f sqrt(c^T Phi_f c) against the true
    sqrt(c^T Phi c)) and pools with its fit's rho. A fit's error thus raises the threshold as much as it
    raises the rate of false detections: most in a history's first weeks, little after a year.

    Parameters
    ----------
    probability : float
        The family's false-detection probability on one day.
    shared : float
        The FORs' correlation.
    lag1 : float
        The days' lag-one correlation.
    baseline : int
        The baseline's length, days.
    discovery : int
        The splits tested: the last *discovery* days.
    known : bool
        A known change's test rather than the blind one.
    directions : int
        The directions tested.
    fit_days : int
        The days the noise was fitted on (:func:`fit_days_bucket`).

    Returns
    -------
    float
        The |z| threshold.
    """
    if known:  # baseline days, the change's day, then the days after it
        rows = [np.r_[step_contrast(baseline, j), np.zeros(discovery - j)] for j in range(1, discovery + 1)]
        ordinal = np.r_[np.arange(baseline), baseline + 1 + np.arange(discovery)]
    else:  # a baseline of its own before each split, the splits' post days ending on the last day
        span = baseline + discovery
        rows = []
        for j in range(1, discovery + 1):
            c = np.zeros(span)
            c[span - j - baseline : span - j] = -1.0 / baseline
            c[span - j :] = 1.0 / j
            rows.append(c)
        ordinal = np.arange(span)
    c = np.array(rows)
    cov = c @ ar1_correlation(ordinal, lag1) @ c.T
    chol = np.linalg.cholesky(cov + 1e-12 * np.eye(len(cov))).astype(np.float32)  # the contrasts' truth
    n_g = MEMBERS.sum(axis=1).astype(np.float32)
    members = MEMBERS.T.astype(np.float32)
    rng = np.random.default_rng(20261127)
    peaks = []
    fits = _simulated_fits(shared, lag1, fit_days, directions)
    for fit, chunk in zip(fits, np.array_split(np.arange(NULL_DRAWS), len(fits)), strict=True):
        days = ar1_correlation(ordinal, fit.lag1)
        believed = fit.scale * np.sqrt(np.einsum("ij,jk,ik->i", c, days, c))[:, None]
        shape = (len(rows), len(chunk), directions)
        g = rng.standard_normal((*shape, 1), dtype=np.float32)
        h = rng.standard_normal((*shape, N_FOR), dtype=np.float32)
        e = np.float32(math.sqrt(shared)) * g + np.float32(math.sqrt(1.0 - shared)) * h
        e = np.tensordot(chol, e, axes=(1, 0))  # the splits correlated as their windows overlap
        e /= believed.astype(np.float32)[:, None, :, None]
        # uniform sigmas: a group's z is (S_G - f n_G S) / sqrt((n_G - f n_G^2)(1 - rho)) (see pooled), S_G
        # the sum of its FORs' standardised differences, S that of all; rho the fit's, per direction
        rho = fit.shared.astype(np.float32)[:, None]  # (directions, 1)
        f = rho / (1.0 - rho + N_FOR * rho)
        norm = np.sqrt((n_g - f * n_g**2) * (1.0 - rho))  # (directions, groups)
        z = (e @ members - f * n_g * e.sum(axis=-1, keepdims=True)) / norm
        peaks.append(np.abs(z).max(axis=(0, 2, 3)))
    return float(np.quantile(np.concatenate(peaks), 1.0 - probability))


@dataclass(frozen=True)
class _Window:
    """A test's days as calendar ordinals: the baseline [pre_from, pre_to), the post days [post_from,
    post_to]; *known* for a known change's test (its day left out between the two)."""

    pre_from: int
    pre_to: int
    post_from: int
    post_to: int
    known: bool = False


def _ar1_factor(n: np.ndarray, lag1: float) -> np.ndarray:
    """The variance of the mean of *n* consecutive days of an AR(1) series over that of white noise:
    1 + 2 sum_{j<n} (1 - j / n) lag1^j."""
    j = np.arange(1, 64)
    n = np.maximum(n, 1)
    return 1.0 + 2.0 * np.sum(np.clip(1.0 - j / n[..., None], 0.0, None) * lag1**j, axis=-1)


def _ar1_cross(n_pre: np.ndarray, n_post: np.ndarray, gap: np.ndarray, lag1: float) -> np.ndarray:
    """The covariance of the means of n_pre days and of the n_post days that follow *gap* days after them
    (1: the next day), for an AR(1) series of unit variance."""
    if lag1 <= 0:
        return np.zeros(np.broadcast(n_pre, n_post, gap).shape)
    a, b = np.maximum(n_pre, 1), np.maximum(n_post, 1)
    return lag1**gap * (1 - lag1**a) * (1 - lag1**b) / ((1 - lag1) ** 2 * a * b)


def _differences(
    ordinal: np.ndarray, y: np.ndarray, s: np.ndarray, windows: list[_Window], noise: Noise
) -> tuple[np.ndarray, np.ndarray]:
    """Per window, FOR and direction the inverse-variance mean of the post days minus that of the
    baseline, and its sigma ((P, N_FOR, C) each), from running sums over the days. The sigma is
    lambda * sqrt(F(n_post) / W_post + F(n_pre) / W_pre - 2 s_pre s_post C): W the windows' summed
    inverse variances, F the AR(1) factor of a window's mean (:func:`_ar1_factor`), C the covariance of
    the two means (:func:`_ar1_cross`), s the windows' RMS sigmas; exact for days in a row with equal
    sigmas, and for any sigmas without day-to-day correlation."""
    ok = np.isfinite(y) & np.isfinite(s) & (s > 0)
    w = np.where(ok, 1.0 / np.where(ok, s, 1.0) ** 2, 0.0)
    zero = np.zeros((1, *y.shape[1:]))
    cw = np.concatenate([zero, np.cumsum(w, axis=0)])
    cwy = np.concatenate([zero, np.cumsum(w * np.where(ok, y, 0.0), axis=0)])
    cn = np.concatenate([zero, np.cumsum(ok, axis=0)])
    edges = np.array([[w_.pre_from, w_.pre_to, w_.post_from, w_.post_to + 1] for w_ in windows])
    p0, p1, q0, q1 = (np.searchsorted(ordinal, edges[:, i]) for i in range(4))
    w_pre, w_post = cw[p1] - cw[p0], cw[q1] - cw[q0]
    n_pre, n_post = cn[p1] - cn[p0], cn[q1] - cn[q0]
    enough = (w_pre > 0) & (w_post > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = (cwy[q1] - cwy[q0]) / w_post - (cwy[p1] - cwy[p0]) / w_pre
        gap = (edges[:, 2] - edges[:, 1] + 1)[:, None, None].astype(float)  # calendar days
        cross = _ar1_cross(n_pre, n_post, gap, noise.lag1) * np.sqrt(n_pre / w_pre * n_post / w_post)
        factor = _ar1_factor(np.arange(len(ordinal) + 1), noise.lag1)  # by the count of days
        f_pre, f_post = factor[n_pre.astype(int)], factor[n_post.astype(int)]
        var = f_post / w_post + f_pre / w_pre - 2 * cross
    sig = np.sqrt(np.maximum(var, 0.0)) * noise.scale
    return np.where(enough, d, np.nan), np.where(enough, sig, np.nan)


def _peaks(
    ordinal: np.ndarray, y: np.ndarray, s: np.ndarray, windows: list[_Window], noise: Noise
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per window the largest |z| over the groups and directions, where (group, direction), and every
    group's estimate and sigma ((P, C, groups))."""
    d, sig = _differences(ordinal, y, s, windows, noise)
    est, est_sig = pooled(np.swapaxes(d, 1, 2), np.swapaxes(sig, 1, 2), noise.shared[:, None])
    z = np.abs(est / est_sig)
    flat = np.where(np.isfinite(z), z, -1.0).reshape(len(windows), -1)
    best = flat.argmax(axis=1)
    c, g = np.unravel_index(best, z.shape[1:])
    return flat.max(axis=1), g, c, est, est_sig


def detect(
    days: list[dt.date],
    y: np.ndarray,
    s: np.ndarray,
    change_days: list[dt.date],
    rules: StepRules,
    fits: FitSource | None = None,
) -> list[Step]:
    """The steps of the series *y* with sigmas *s* (assessed days *days*, ascending; (T, N_FOR, C), NaN
    where nothing reliable was measured) that the daily evaluations up to the last day would have found,
    given the known changes' days *change_days*, whose split lies in the last ``baseline_days`` days (see
    the module docstring). The series need hold no more than the last :func:`replay_reach` days when
    *fits* gives the noise of the days before.

    Parameters
    ----------
    days : list of datetime.date
        The assessed days, ascending.
    y : numpy.ndarray
        The values, shape (T, N_FOR, C); NaN where nothing reliable was measured.
    s : numpy.ndarray
        Their sigmas.
    change_days : list of datetime.date
        The known changes' days.
    rules : StepRules
        The detector's parameters.
    fits : callable, optional
        The :class:`FittedNoise` of every day before an ordinal (the store's kept fits); by default
        fitted from the series given (:func:`fitted_before`), which must then hold the whole history.

    Returns
    -------
    list of Step
        The steps found.
    """
    if len(days) < MIN_HISTORY_DAYS:
        return []
    ordinal = np.array([d.toordinal() for d in days])
    last = int(ordinal[-1])
    start = last - 2 * rules.baseline_days + 1  # the replay's first day
    b, k = rules.baseline_days, rules.discovery_days
    source: FitSource = fits or (lambda before: fitted_before(ordinal, y, s, before))
    noises: dict[int, FittedNoise] = {}
    judged: dict[int, _Fit | None] = {}

    def _noise(before: int) -> FittedNoise:
        if before not in noises:
            noises[before] = source(before)
        return noises[before]

    def _fitted(split: int) -> _Fit | None:
        """The fit a test of *split* uses: the days before the refit date on or before its baseline
        (REFIT_DAYS apart, on fixed dates), or early in a history every day before it. It depends on the
        split alone, so every evaluation decides a split alike: once, not anew each day."""
        anchor = split - b - (split - b - REFIT_EPOCH) % REFIT_DAYS
        if _noise(anchor).days < MIN_HISTORY_DAYS:
            anchor = split
        if anchor not in judged:
            judged[anchor] = _fit(y, s, _noise(anchor), rules)
        return judged[anchor]

    changes = sorted({c.toordinal() for c in change_days})
    replay = [int(t) for t in ordinal[ordinal >= start]]
    accepted: list[tuple[_Window, int, float, int, int]] = []  # (window, seen, z, group, direction)
    broken = -(10**9)  # where the latest accepted step's new level begins: no baseline reaches before it
    while replay:
        windows: list[_Window] = []
        seen: list[int] = []
        for t in replay:
            for x in changes:
                if 1 <= t - x <= k and x >= broken:
                    windows.append(_Window(max(x - b, broken), x, x + 1, t, known=True))
                    seen.append(t)
            for tau in ordinal[(ordinal > t - k) & (ordinal <= t) & (ordinal > broken)]:
                if any(tau <= x <= t for x in changes):  # a change's day in it: its own test's
                    continue
                windows.append(_Window(max(int(tau) - b, broken), int(tau), int(tau), t))
                seen.append(t)
        usable = [
            np.count_nonzero((ordinal >= w.pre_from) & (ordinal < w.pre_to)) >= rules.min_baseline_days
            and _fitted(w.pre_to) is not None
            for w in windows
        ]
        windows = [w for w, ok in zip(windows, usable, strict=True) if ok]
        seen = [t for t, ok in zip(seen, usable, strict=True) if ok]
        if not windows:
            break
        z, g, c, limit = (np.zeros(len(windows)) for _ in range(4))
        by_fit: dict[int, list[int]] = {}
        for i, w in enumerate(windows):
            by_fit.setdefault(id(_fitted(w.pre_to)), []).append(i)
        for members in by_fit.values():
            f = _fitted(windows[members[0]].pre_to)
            assert f is not None
            zz, gg, cc, _, _ = _peaks(ordinal, y, f.sigma, [windows[i] for i in members], f.noise)
            z[members], g[members], c[members] = zz, gg, cc
            limit[members] = [f.at_change if windows[i].known else f.blind for i in members]
        over = z > limit
        if not over.any():
            break
        day = seen[int(np.flatnonzero(over)[0])]  # the first day anything is found; a known change first
        on_day = [i for i in np.flatnonzero(over) if seen[i] == day]
        known = [i for i in on_day if windows[i].known]
        i = int(known[0] if known else max(on_day, key=lambda j: z[j]))
        w = windows[i]
        near = [x for x in changes if abs(w.pre_to - x) <= rules.attribution_days and x >= broken]
        if not w.known and near:  # a blind step at a known change: dated and measured as the change
            w = _Window(max(near[0] - b, broken), near[0], near[0] + 1, day, known=True)
        accepted.append((w, day, float(z[i]), int(g[i]), int(c[i])))
        broken = w.post_from
        replay = [t for t in replay if t > day]
    out = []
    for i, (w, *_) in enumerate(accepted):
        f = _fitted(w.pre_to)
        if w.post_from > last - b and f is not None:
            out.append(_step(ordinal, y, f.sigma, f.noise, changes, rules, accepted, i))
    return out


@dataclass(frozen=True)
class _Fit:
    """What a test is judged by: the noise fitted, the sigmas floored at half their FOR's usual one, and
    the thresholds of the blind test and of the test at a known change."""

    noise: Noise
    sigma: np.ndarray
    blind: float
    at_change: float


def _fit(y: np.ndarray, s: np.ndarray, fitted: FittedNoise, rules: StepRules) -> _Fit | None:
    """The :class:`_Fit` of the noise *fitted* for the series *y*, *s*: its sigmas floored at half their
    FOR's usual one; None when the noise could not be fitted."""
    if fitted.noise is None:
        return None
    noise = fitted.noise
    rho = round(float(np.max(noise.shared)) * 20) / 20  # the thresholds on a grid of 0.05
    phi = round(noise.lag1 * 20) / 20
    b, k, c = rules.baseline_days, rules.discovery_days, y.shape[-1]
    n = fit_days_bucket(fitted.days)
    return _Fit(
        noise,
        np.fmax(s, 0.5 * fitted.typical),
        threshold(RATE_MARGIN * rules.rate_per_year / 365.0, rho, phi, b, k, False, c, n),
        threshold(RATE_MARGIN * rules.rate_at_change, rho, phi, b, k, True, c, n),
    )


def window_mean(
    ordinal: np.ndarray, y: np.ndarray, s: np.ndarray, first: int, last: int, noise: Noise
) -> tuple[np.ndarray, np.ndarray]:
    """Per FOR and direction the inverse-variance mean of the days *first*..*last* (ordinals, both
    included) and its sigma, lambda * sqrt(F(n) / W) (W the summed inverse variances, F the AR(1) factor
    of the mean of n days: :func:`_ar1_factor`); NaN where no day was measured.

    Parameters
    ----------
    ordinal : numpy.ndarray
        The days' ordinals, shape (T,).
    y : numpy.ndarray
        The values (urad, or K for the bias), shape (T, N_FOR, C).
    s : numpy.ndarray
        Their sigmas, same shape.
    first, last : int
        The window's ordinals, both included.
    noise : Noise
        The fitted noise.

    Returns
    -------
    mean, sigma : numpy.ndarray
        Per FOR and direction; NaN where no day was measured.
    """
    days = (ordinal >= first) & (ordinal <= last)
    ok = days[:, None, None] & np.isfinite(y) & np.isfinite(s) & (s > 0)
    w = np.where(ok, 1.0 / np.where(ok, s, 1.0) ** 2, 0.0)
    total = w.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.sum(w * np.where(ok, y, 0.0), axis=0) / total
        sigma = np.sqrt(_ar1_factor(ok.sum(axis=0), noise.lag1) / total) * noise.scale
    return np.where(total > 0, mean, np.nan), np.where(total > 0, sigma, np.nan)


def move(
    ordinal: np.ndarray,
    y: np.ndarray,
    s: np.ndarray,
    before: tuple[int, int],
    after: tuple[int, int],
    noise: Noise,
) -> tuple[np.ndarray, np.ndarray]:
    """Per FOR and direction the mean of the days *after* minus that of the days *before* (ordinal ranges,
    both ends included) and its sigma, as the jump rule measures a step (:func:`_differences`: the two
    windows' correlation through the days' included).

    Parameters
    ----------
    ordinal : numpy.ndarray
        The days' ordinals, shape (T,).
    y : numpy.ndarray
        The values (urad, or K for the bias), shape (T, N_FOR, C).
    s : numpy.ndarray
        Their sigmas, same shape.
    before, after : tuple of int
        The two windows' ordinal ranges, both ends included.
    noise : Noise
        The fitted noise.

    Returns
    -------
    move, sigma : numpy.ndarray
        Per FOR and direction.
    """
    d, sig = _differences(ordinal, y, s, [_Window(before[0], before[1] + 1, after[0], after[1])], noise)
    return d[0], sig[0]


def _step(
    ordinal: np.ndarray,
    y: np.ndarray,
    s: np.ndarray,
    noise: Noise,
    changes: list[int],
    rules: StepRules,
    accepted: list[tuple[_Window, int, float, int, int]],
    i: int,
) -> Step:
    """The *i*-th accepted step measured over its baseline and up to ``size_days`` after it (before the
    next one), attributed to a known change within ``attribution_days`` of its split."""
    w, seen, z, g, c = accepted[i]
    split = w.pre_to  # the known change's day, or the first day at the new level
    following = accepted[i + 1][0].pre_to if i + 1 < len(accepted) else int(ordinal[-1]) + 1
    post_from = w.post_from if w.post_from <= ordinal[-1] else w.pre_to  # on the change's day: that day
    sized = _Window(w.pre_from, w.pre_to, post_from, min(following - 1, post_from + rules.size_days - 1))
    d, sig = _differences(ordinal, y, s, [sized], noise)
    _, _, _, est, est_sig = _peaks(ordinal, y, s, [sized], noise)
    near = [j for j, x in enumerate(changes) if abs(split - x) <= rules.attribution_days]
    change = changes.index(split) if w.known else (near[0] if near else None)
    pooled_size = float(est[0, c, g])
    return Step(
        dt.date.fromordinal(split),
        change,
        dt.date.fromordinal(seen),
        GROUPS[g][0],
        c,
        z,
        pooled_size,
        float(est_sig[0, c, g]),
        d[0],
        sig[0],
        bool(abs(pooled_size) >= rules.practical),
    )
