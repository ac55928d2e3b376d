"""The uncertainty of a day's estimates: the delete-one-granule jackknife.

The error of an offset varies from scene to scene: on real radiances two halves of the same day's granules
disagree by far more than resampling scans within granules allows (``docs/science.md``, "Honest sigmas").
So the unit of resampling is the granule: replicate g leaves granule g out, and with G granules and
estimates t_g the variance is (Tukey; Efron and Stein 1981)

    var = (G - 1) / G * sum_g (t_g - mean t)^2 = (G - 1) * var_0(t_g),

which is unbiased for a mean and conservative (too large in expectation) for a smooth statistic: the
scene-to-scene part enters by construction, with no factor fitted to data. A granule bootstrap would need
hundreds of replicates to say as much with as few granules as a day brings (6-14); the jackknife needs G.

**Few granules.** With G groups that variance is itself estimated with nu = G - 1 degrees of freedom, so an
error divided by it is Student-t distributed, whose variance is nu / (nu - 2), not 1: with 5 granules, twice
what a normal error would have (errors beyond two such sigmas: ~12 % instead of 5 %). The sigma reported is
the t's standard deviation, sqrt(var nu / (nu - 2)), so that error / sigma has unit variance whatever G is:
a factor of 1.41 with 5 granules, 1.13 with 10, 1.09 with 14, derived from G alone.

With fewer than :data:`MIN_GRANULES` granules the scene-to-scene part cannot be told from so few, and the
scans are the groups instead (what they say is then the scatter within the granule(s)); fewer than
:data:`MIN_GRANULES` groups give no sigma.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_GRANULES = 4  # groups from which a sigma is stated (nu = 3, nu / (nu - 2) = 3); granules from this many


@dataclass(frozen=True)
class Jackknife:
    """Delete-one-group replicates over N samples: *counts* (G, N) weighs each sample 1 in each replicate
    but the one leaving its group out (0)."""

    counts: np.ndarray

    @classmethod
    def of(cls, granule: np.ndarray, scan: np.ndarray) -> Jackknife | None:
        """The replicates of samples from granules *granule* (N,) and scans *scan* (N,) within them: one per
        granule from :data:`MIN_GRANULES` granules, else one per scan; None from fewer groups than that."""
        granule, scan = np.asarray(granule), np.asarray(scan)
        if len(np.unique(granule)) >= MIN_GRANULES:
            groups = granule
        else:
            groups = np.unique(np.stack([granule, scan], 1), axis=0, return_inverse=True)[1].reshape(-1)
        ids, member = np.unique(groups, return_inverse=True)
        if len(ids) < MIN_GRANULES:
            return None
        return cls((member[None, :] != np.arange(len(ids))[:, None]).astype(float))

    @property
    def groups(self) -> int:
        """G, the number of replicates."""
        return len(self.counts)

    def sigma(self, replicates: np.ndarray) -> np.ndarray:
        """The uncertainty of the statistic whose G *replicates* are along axis 0: the jackknife variance
        times nu / (nu - 2), nu = G - 1 (module docstring); NaN replicates are left out, G counting those
        that remain (NaN below MIN_GRANULES)."""
        t = np.asarray(replicates, float)
        g = np.sum(np.isfinite(t), axis=0)
        nu = g - 1.0
        with np.errstate(invalid="ignore", divide="ignore"):
            var = (g - 1) * np.nanvar(t, axis=0) * nu / (nu - 2)
            return np.where(g >= MIN_GRANULES, np.sqrt(var), np.nan)
