"""The geolocation read in a second VIIRS band: the offsets assessed in M15 beside I5's, and their difference.

The same perturbation assessment (Wang et al. 2017, sections 2.3-2.4) run on the same CrIS granules against
VIIRS M15 (on the M grid, its own GEO) gives a second estimate of each FOR's offsets. Both see the same
scenes, so their errors are correlated and the sigma of their difference is not the two sigmas in quadrature:
it is the jackknife's over paired replicates, the difference of the two bands' replicates that leave out the
same granules (:mod:`monitor.estimation.jackknife`), with the larger of the two FORs' correlation factors. A
CrIS error moves both bands alike; a difference beyond :data:`DIFFER_SIGMAS` of its sigmas is VIIRS's
(band-to-band registration or its geolocation product), flagged ``bands_differ`` on the FOR.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from monitor.core.result import FLAG_BANDS_DIFFER, AssessmentResult, ForOffset, ForReplicates
from monitor.estimation.jackknife import MIN_GRANULES, replicate_sigma

DIFFER_SIGMAS = 3.0  # a difference beyond this many of its sigmas is flagged


def paired_sigma_urad(first: ForReplicates | None, second: ForReplicates | None) -> tuple[float, float]:
    """The sigma of *second* minus *first* from their replicates paired by the granules they leave out.

    Parameters
    ----------
    first, second : ForReplicates or None
        One FOR's replicates in each band.

    Returns
    -------
    tuple of float
        The in-track and cross-track sigmas, urad; NaN where fewer than
        :data:`~monitor.estimation.jackknife.MIN_GRANULES` groups are common to both.
    """
    if first is None or second is None:
        return math.nan, math.nan
    at = {g: i for i, g in enumerate(first.groups)}
    common = [(at[g], j) for j, g in enumerate(second.groups) if g in at]
    if len(common) < MIN_GRANULES:
        return math.nan, math.nan
    i, j = (np.array(v) for v in zip(*common, strict=True))
    d = np.stack([second.alpha_urad[j] - first.alpha_urad[i], second.beta_urad[j] - first.beta_urad[i]], 1)
    sigma = replicate_sigma(d) * max(first.factor, second.factor)
    return float(sigma[0]), float(sigma[1])


def _paired(f: ForOffset, o: ForOffset, sigma: tuple[float, float]) -> ForOffset:
    """FOR *f* (I5) with the offsets of *o* (M15) and their difference, flagged where it is beyond doubt."""
    d_alpha, d_beta = o.d_alpha_urad - f.d_alpha_urad, o.d_beta_urad - f.d_beta_urad
    beyond = any(
        math.isfinite(d) and math.isfinite(s) and abs(d) > DIFFER_SIGMAS * s
        for d, s in ((d_alpha, sigma[0]), (d_beta, sigma[1]))
    )
    flags = f.flags + ((FLAG_BANDS_DIFFER,) if beyond and f.reliable and o.reliable else ())
    return replace(
        f,
        d_alpha_urad_M15=o.d_alpha_urad,
        d_beta_urad_M15=o.d_beta_urad,
        sigma_alpha_urad_M15=o.sigma_alpha_urad,
        sigma_beta_urad_M15=o.sigma_beta_urad,
        m15_minus_i5_alpha_urad=d_alpha,
        m15_minus_i5_beta_urad=d_beta,
        sigma_m15_minus_i5_alpha_urad=sigma[0],
        sigma_m15_minus_i5_beta_urad=sigma[1],
        flags=tuple(sorted(set(flags))),
    )


def with_second_band(result: AssessmentResult, second: AssessmentResult) -> AssessmentResult:
    """The day's I5 *result* with each FOR's offsets assessed in M15 (*second*) and their paired difference.

    Parameters
    ----------
    result : AssessmentResult
        The day's assessment in I5, with its replicates.
    second : AssessmentResult
        The same granules assessed in M15, with its replicates.

    Returns
    -------
    AssessmentResult
        A copy whose FORs carry ``d_alpha_urad_M15`` and the rest, ``m15_minus_i5_*`` with their sigmas, and
        ``bands_differ`` where the difference exceeds :data:`DIFFER_SIGMAS` sigmas on two reliable FORs.
    """
    others = {o.for_index: o for o in second.fors}
    first_reps = result.replicates or [None] * len(result.fors)
    second_reps = {o.for_index: r for o, r in zip(second.fors, second.replicates or [], strict=False)}
    fors = [
        _paired(f, others[f.for_index], paired_sigma_urad(r, second_reps.get(f.for_index)))
        if f.for_index in others
        else f
        for f, r in zip(result.fors, first_reps, strict=True)
    ]
    return replace(result, fors=fors)
