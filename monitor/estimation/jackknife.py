"""The uncertainty of a day's estimates, derived: the delete-one-granule jackknife (a run of granules per
replicate on a long day), the t's quantile for few granules, and the granules counted as fewer when
consecutive ones share their scenes.

**The unit.** The error of an offset varies from scene to scene: on real radiances two halves of a day's
granules disagree by far more than resampling scans within granules allows (``docs/science.md``). So the unit
of resampling is the granule: replicate g leaves granule g out, and with G granules and estimates t_g the
standard error is (Tukey; Efron and Stein 1981)

    se^2 = (G - 1) / G * sum_g (t_g - mean t)^2 = (G - 1) * var_0(t_g),

unbiased for a mean and conservative for a smooth statistic. A granule bootstrap would need hundreds of
replicates to say as much with the 6-14 granules a day brings; the jackknife needs G.

**Few granules.** se is itself estimated with nu = G - 1 degrees of freedom, so error / se is Student-t
distributed, not normal. The sigma reported is the one whose two-sigma interval has the normal's coverage
(95.45 %, what a reader of "within 2 sigma" expects):

    sigma = se * t_nu(Phi(2)) / 2,

a factor of 1.33 with 6 granules, 1.12 with 14 (the t quantile, not its standard deviation: the quantile is
finite for every nu >= 1 and is what the 2-sigma statements of the product test).

**Long days.** Each replicate repeats the whole estimate over the samples it keeps, so G replicates of a day
of G granules cost G^2 granules' worth. Beyond
:data:`MAX_GROUPS` granules each replicate therefore leaves out a run of consecutive granules
(:func:`granule_runs`: H = MAX_GROUPS runs, their lengths differing by at most one), the delete-a-group
jackknife (Kott 2001) with the same formula over H groups and nu = H - 1; its cost is H estimates, linear in
the day. Runs of consecutive granules are also the block jackknife's groups (Kunsch 1989): the correlation of
neighbours stays within a run, and what crosses from one run to the next is read as below, between runs.
H = 20 costs the sigma little: t_19 makes a factor of 1.07 (1.04 at 30), and a standard error from 20
groups is itself uncertain by ~16 % (1 / sqrt(2 nu)).

**Consecutive granules.** Granules a minute apart share cloud systems, so their estimates are not
independent, and G overstates the information. With a lag-one correlation rho between the replicates of
granules that follow each other, the variance of a mean of G is that of G_eff = G (1 - rho) / (1 + rho)
independent ones (the AR(1) effective sample size), and nu = G_eff - 1. rho is a property of the day's scenes,
not of one FOR, so it is estimated once per day, pooled over every FOR and direction
(:func:`adjacent_correlation`), corrected for the bias of a lag-one correlation of G values about their mean
(-1 / G where the values are independent), and counted only where it exceeds twice its standard error over
the day's pairs of consecutive granules (the FORs share their granules' scenes, so the pairs are the
independent units; a day of five granules has at most four, and a correlation read from them alone would
make its sigmas noisier than the ones it corrects). Granules spread over the day (the daily
run's) have no neighbours, so rho = 0 and G_eff = G. On a long day the same holds for the runs: rho is that of
consecutive runs, one following the other where the first granule of the later run directly follows the
last of the earlier. :func:`correlation_factor` is what rho does to a sigma.

No constant is fitted to data: G, rho and the t distribution make the factor.

With fewer than :data:`MIN_GRANULES` granules the scans are the groups instead (what they say is then the
scatter within the granule(s), and rho is not applied); fewer groups than that give no sigma.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from monitor.core.constants import CRIS_GRANULE_US

MIN_GRANULES = 4  # groups from which a sigma is stated; granules as groups from this many
TWO_SIGMA = float(stats.norm.cdf(2.0))  # the normal's one-sided probability within 2 sigma
MAX_CORRELATION = 0.95  # rho is held below this: above it a day has less than one granule's worth
MAX_GROUPS = 20  # replicates at most: beyond this many granules each leaves out a run of them


def t_factor(nu: float) -> float:
    """The factor from a standard error to the sigma whose 2-sigma interval covers as a normal's.

    Parameters
    ----------
    nu : float
        The degrees of freedom.

    Returns
    -------
    float
        t_nu(Phi(2)) / 2; NaN for nu < 1.
    """
    return float(stats.t.ppf(TWO_SIGMA, nu) / 2.0) if nu >= 1 else math.nan


def effective_groups(groups: int, rho: float) -> float:
    """G_eff of granules whose neighbours correlate: G (1 - rho) / (1 + rho).

    Parameters
    ----------
    groups : int
        G, the granules (or runs of them) the replicates leave out.
    rho : float
        The lag-one correlation of consecutive granules' replicates.

    Returns
    -------
    float
        The effective number of independent granules.
    """
    return groups * (1.0 - rho) / (1.0 + rho)


def correlation_factor(groups: int, rho: float) -> float:
    """What a lag-one correlation of consecutive granules does to a sigma: sqrt(G / G_eff) t(G_eff - 1) / t(G
    - 1).

    Parameters
    ----------
    groups : int
        G, the granules (or runs of them) the replicates leave out.
    rho : float
        The lag-one correlation.

    Returns
    -------
    float
        The factor; NaN where G_eff - 1 < 1.
    """
    if rho <= 0:
        return 1.0
    g_eff = effective_groups(groups, rho)
    return math.sqrt(groups / g_eff) * t_factor(g_eff - 1.0) / t_factor(groups - 1.0)


def follows_in_time(starts_s: Sequence[float]) -> np.ndarray:
    """Per granule, whether it directly follows the one before.

    Parameters
    ----------
    starts_s : sequence of float
        The granules' start times, s, in the order given.

    Returns
    -------
    numpy.ndarray
        bool per granule: it starts at most 1.5 CrIS granules after the one before (consecutive granules start
        32 s apart).
    """
    s = np.asarray(starts_s, float)
    gap = np.diff(s, prepend=np.nan)
    return (gap > 0) & (gap <= 1.5 * CRIS_GRANULE_US * 1e-6)


def jackknife_sigma(replicates: np.ndarray) -> float:
    """The delete-one jackknife standard error: sqrt((G - 1)/G sum (x_g - mean)^2).

    Parameters
    ----------
    replicates : numpy.ndarray
        The G replicates' estimates.

    Returns
    -------
    float
        The standard error, in the estimates' unit.
    """
    g = len(replicates)
    return float(np.sqrt((g - 1) / g * np.sum((replicates - replicates.mean()) ** 2)))


def granule_runs(granules: np.ndarray) -> list[np.ndarray]:
    """The granules each replicate leaves out.

    Parameters
    ----------
    granules : numpy.ndarray
        The granule of every sample (ids in time order).

    Returns
    -------
    list of numpy.ndarray
        Each granule on its own up to :data:`MAX_GROUPS` granules, else MAX_GROUPS runs of consecutive ones
        whose lengths differ by at most one.
    """
    ids = np.unique(granules)
    return np.array_split(ids, min(len(ids), MAX_GROUPS))


def adjacent_correlation(replicates: Sequence[tuple[np.ndarray, np.ndarray]], follows: np.ndarray) -> float:
    """The day's lag-one correlation of the replicates of consecutive granules.

    Per pair of replicates of which the second leaves out the granule after the first's last, and that
    granule directly follows it in time, the mean product over the series; rho their mean. The series of
    one day share their granules' scenes, so the pairs, not the products, are the independent units.

    Parameters
    ----------
    replicates : sequence of (numpy.ndarray, numpy.ndarray)
        Per series, the first and last granule each replicate leaves out (G, 2) and the replicates (G, k), one
        column a series, each on its own scale.
    follows : numpy.ndarray
        Per granule, whether it directly follows the one before (:func:`follows_in_time`).

    Returns
    -------
    float
        rho, corrected for the -1 / G bias; 0 unless it exceeds twice its standard error over the pairs, and
        where no granule follows another.
    """
    products: dict[int, list[float]] = {}
    lengths = []
    for spans, reps in replicates:
        r = np.asarray(reps, float)
        ok = np.all(np.isfinite(r), axis=1)
        spans, r = np.asarray(spans).reshape(-1, 2)[ok], r[ok]
        if len(spans) < MIN_GRANULES:
            continue
        r = r - r.mean(axis=0)
        scale = np.sqrt(np.mean(r * r, axis=0))
        r = np.divide(r, scale, out=np.zeros_like(r), where=scale > 0)
        first = spans[1:, 0]
        adjacent = np.flatnonzero((first == spans[:-1, 1] + 1) & follows[first])
        for i in adjacent:
            products.setdefault(int(first[i]), []).extend(r[i] * r[i + 1])
        lengths.append(len(spans))
    pairs = np.array([np.mean(v) for v in products.values()])
    if len(pairs) < 2:
        return 0.0
    rho = float(pairs.mean()) + 1.0 / float(np.mean(lengths))
    se = float(pairs.std(ddof=1)) / np.sqrt(len(pairs))
    return float(min(rho, MAX_CORRELATION)) if rho > 2 * se else 0.0


def uncertainty_note(granules: int, rho: float) -> str:
    """What a result says of how its sigmas count its granules.

    Parameters
    ----------
    granules : int
        The day's granules.
    rho : float
        The lag-one correlation of consecutive granules counted.

    Returns
    -------
    str
        The note, for the result's ``notes``.
    """
    if granules < MIN_GRANULES:
        return (
            f"sigmas: {granules} granule(s), the scans within them resampled (the scene-to-scene part unseen)"
        )
    if granules > MAX_GROUPS:
        return (
            f"sigmas: delete-a-group jackknife over {granules} granules in {MAX_GROUPS} runs of consecutive "
            f"ones, t quantile for the 2-sigma level; consecutive runs correlate by {rho:.2f}: counted as "
            f"{effective_groups(MAX_GROUPS, rho):.1f}"
        )
    return (
        f"sigmas: delete-one-granule jackknife over {granules} granules, t quantile for the 2-sigma level; "
        f"consecutive granules correlate by {rho:.2f}: counted as {effective_groups(granules, rho):.1f}"
    )


def replicate_sigma(replicates: np.ndarray) -> np.ndarray:
    """The sigma of a statistic from its delete-a-group replicates, its groups independent.

    Parameters
    ----------
    replicates : numpy.ndarray
        The G replicates along axis 0.

    Returns
    -------
    numpy.ndarray
        The jackknife's standard error times t_factor(G - 1), in the statistic's unit; NaN replicates are left
        out, G counting those that remain (NaN below MIN_GRANULES).
    """
    t = np.asarray(replicates, float)
    g = np.sum(np.isfinite(t), axis=0)
    factor = np.vectorize(t_factor, otypes=[float])(g - 1.0)
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        # a statistic no granule measured has no variance: NaN, below MIN_GRANULES anyway (no warning)
        warnings.simplefilter("ignore", RuntimeWarning)
        se = np.sqrt((g - 1) * np.nanvar(t, axis=0))
        return np.where(g >= MIN_GRANULES, se * factor, np.nan)


@dataclass(frozen=True)
class Jackknife:
    """Delete-one-group replicates over N samples: *counts* (G, N) weighs each sample 1 in each replicate
    but the one leaving its group out (0); *granules* (G, 2) the first and last granule each group leaves
    out, where the groups are granules or runs of them (None where they are scans)."""

    counts: np.ndarray
    granules: np.ndarray | None = None

    @classmethod
    def of(cls, granule: np.ndarray, scan: np.ndarray) -> Jackknife | None:
        """The replicates of samples from granules and scans.

        Parameters
        ----------
        granule : numpy.ndarray
            Each sample's granule (ids in time order), shape (N,).
        scan : numpy.ndarray
            Each sample's scan within its granule, shape (N,).

        Returns
        -------
        Jackknife or None
            One replicate per granule from :data:`MIN_GRANULES` granules (per run of consecutive granules
            beyond :data:`MAX_GROUPS`, :func:`granule_runs`), else one per scan; None from fewer groups than
            that.
        """
        granule, scan = np.asarray(granule), np.asarray(scan)
        if len(np.unique(granule)) >= MIN_GRANULES:
            runs = granule_runs(granule)
            member = np.searchsorted([r[-1] for r in runs], granule)
            counts = (member[None, :] != np.arange(len(runs))[:, None]).astype(float)
            return cls(counts, np.array([(r[0], r[-1]) for r in runs]))
        groups = np.unique(np.stack([granule, scan], 1), axis=0, return_inverse=True)[1].reshape(-1)
        ids, member = np.unique(groups, return_inverse=True)
        if len(ids) < MIN_GRANULES:
            return None
        return cls((member[None, :] != np.arange(len(ids))[:, None]).astype(float))

    @property
    def groups(self) -> int:
        """G, the number of replicates.

        Returns
        -------
        int
            G.
        """
        return len(self.counts)

    # the sigma of a statistic from the replicates (their groups independent): :func:`replicate_sigma`
    sigma = staticmethod(replicate_sigma)
