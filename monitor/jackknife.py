"""The uncertainty of a day's estimates: the delete-one-granule jackknife.

The error of an offset varies from scene to scene: on real radiances two halves of the same day's granules
disagree by far more than resampling scans within granules allows (``docs/science.md``, "Honest sigmas").
So the unit of resampling is the granule: replicate g leaves granule g out, and with G granules and
estimates t_g the variance is (Tukey; Efron and Stein 1981)

    var = (G - 1) / G * sum_g (t_g - mean t)^2 = (G - 1) * var_0(t_g),

which is unbiased for a mean and conservative (too large in expectation) for a smooth statistic: the
scene-to-scene part enters by construction, with no factor fitted to data. A delete-one replicate of a
granule bootstrap would need hundreds of replicates to say as much with as few granules as a day brings
(6-14); the jackknife needs G.

With fewer than :data:`MIN_GRANULES` granules the scene-to-scene part cannot be told from two or one, and
the scans are the groups instead (what they say is then the scatter within the granule(s)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_GRANULES = 3  # granules from which they are the jackknife's groups (fewer: the scans are)


@dataclass(frozen=True)
class Jackknife:
    """Delete-one-group replicates over N samples: *counts* (G, N) weighs each sample 1 in each replicate
    but the one leaving its group out (0)."""

    counts: np.ndarray

    @classmethod
    def of(cls, granule, scan) -> Jackknife | None:
        """The replicates of samples from granules *granule* (N,) and scans *scan* (N,) within them: one per
        granule from :data:`MIN_GRANULES` granules, else one per scan; None from fewer than two groups."""
        granule, scan = np.asarray(granule), np.asarray(scan)
        if len(np.unique(granule)) >= MIN_GRANULES:
            groups = granule
        else:
            groups = np.unique(np.stack([granule, scan], 1), axis=0, return_inverse=True)[1].reshape(-1)
        ids, member = np.unique(groups, return_inverse=True)
        if len(ids) < 2:
            return None
        return cls((member[None, :] != np.arange(len(ids))[:, None]).astype(float))

    @property
    def groups(self) -> int:
        """G, the number of replicates."""
        return len(self.counts)

    def sigma(self, replicates) -> np.ndarray:
        """The jackknife standard error of the statistic whose G *replicates* are along axis 0 (NaN
        replicates are left out, the factor kept for the G that remain)."""
        t = np.asarray(replicates, float)
        g = np.sum(np.isfinite(t), axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.sqrt((g - 1) * np.nanvar(t, axis=0))
