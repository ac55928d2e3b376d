"""CrIS minus VIIRS brightness temperature per VIIRS band and FOR over the FOVs uniform in VIIRS: the day's
radiometric comparison, on the day's mapping (:mod:`monitor.matchup`).

**The comparison** is Tobin et al. (2013)'s: in each band, CrIS's spectrum convolved with the band's
spectral response against the VIIRS pixels inside the CrIS FOV averaged with the FOV's spatial response,
both as brightness temperatures (:mod:`monitor.matchup.run`), on the assessed geolocation and the fitted
response.

**The uniformity test.** A FOV counts where its scene is uniform in VIIRS: the response-weighted standard
deviation of its pixels' BT in that band is at most ``uniform_std_k`` and valid pixels cover at least
``min_coverage`` of the response. In a scene whose BT varies by s across the FOV, a residual geolocation
error e moves the FOV's mean by about s e / FOV, and a mis-modelled footprint by a share of s; on uniform
scenes both vanish and the difference is the two calibrations' and the spectral responses'. M13 counts only
where the scene is warmer than its band's ``min_scene_k`` (CrIS's short-wave noise at cold scenes).

**The day's value and its sigma.** Per band and FOR, the mean difference over the day's uniform FOVs; its
sigma the delete-one-granule jackknife of that mean (:mod:`monitor.estimation.jackknife`: runs of
granules beyond its MAX_GROUPS, the scans as groups below MIN_GRANULES granules, the t factor for few
groups), the unit the offsets' sigmas resample too. The same per band by FOV (1..9), by 10 K bin of the
scene's VIIRS BT and by the orbit's node (the latitude rising or falling from scan to scan).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from monitor.core.bands import BANDS
from monitor.core.constants import N_FOR, N_FOV
from monitor.core.result import AssessmentResult, DifferenceMap, RadiometryBin
from monitor.core.vocabulary import BinnedBy
from monitor.estimation.jackknife import MIN_GRANULES, granule_runs, t_factor
from monitor.matchup.product import Matchup

SCENE_BIN_K = 10.0  # width of the scene-temperature bins
MIN_FOVS = 10  # fewest uniform FOVs in a FOR or bin for a value


@dataclass(frozen=True)
class Uniformity:
    """The uniformity test: the largest response-weighted BT standard deviation of a FOV's VIIRS pixels
    (K), and the least share of the FOV's response that valid pixels cover."""

    max_std_k: float
    min_coverage: float


@dataclass(frozen=True)
class BandDifference:
    """One band's day: per FOR (index 0 = FOR 1) the mean CrIS minus VIIRS BT over its uniform FOVs, its
    jackknife sigma (K) and the FOVs counted; NaN where fewer than :data:`MIN_FOVS` or no sigma."""

    band: str
    mean_k: np.ndarray
    sigma_k: np.ndarray
    n: np.ndarray


@dataclass(frozen=True)
class DayRadiometry:
    """The day's comparison in every band mapped, its bins (:class:`RadiometryBin`), and every FOV of the
    granule with the most uniform FOVs in each band (:class:`DifferenceMap`)."""

    bands: tuple[BandDifference, ...]
    bins: tuple[RadiometryBin, ...]
    maps: tuple[DifferenceMap, ...]


def _groups(matchup: Matchup) -> np.ndarray:
    """The jackknife group of every scan: its granule's run (:func:`granule_runs`), or the scan itself
    where fewer than MIN_GRANULES granules were mapped."""
    granule = np.asarray(matchup.granule_of_scan)
    if len(np.unique(granule)) < MIN_GRANULES:
        return np.arange(granule.size)
    group = np.empty(granule.size, int)
    for g, members in enumerate(granule_runs(granule)):
        group[np.isin(granule, members)] = g
    return group


def ascending(matchup: Matchup) -> np.ndarray:
    """Whether each scan is on the ascending node: the scene centre's latitude rises to the next scan of
    its granule (from the previous one at a granule's last scan).

    Parameters
    ----------
    matchup : Matchup
        The mapping.

    Returns
    -------
    numpy.ndarray
        Shape (scans,), bool.
    """
    lat = matchup.latitude_deg[:, N_FOR // 2, N_FOV // 2]
    granule = np.asarray(matchup.granule_of_scan)
    rising = np.zeros(lat.size, bool)
    for g in np.unique(granule):
        idx = np.flatnonzero(granule == g)
        if idx.size > 1:
            rising[idx] = np.gradient(lat[idx]) > 0
    return rising


def _jackknifed(
    d: np.ndarray, keep: np.ndarray, key: np.ndarray, n_keys: int, group: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean of *d* over the samples kept, per key 0..n_keys-1, with its delete-a-group jackknife sigma.

    *d*, *keep*, *key* (the key of each sample) and *group* (each sample's jackknife group) share one shape.
    Returns (mean, sigma, n) per key; mean NaN below MIN_FOVS, sigma NaN with fewer than two groups.
    """
    k, g, v = key[keep], group[keep], d[keep]
    n_groups = int(group.max()) + 1 if group.size else 0
    flat = k * n_groups + g
    sums = np.bincount(flat, v, n_keys * n_groups).reshape(n_keys, n_groups)
    counts = np.bincount(flat, None, n_keys * n_groups).reshape(n_keys, n_groups)
    n = counts.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(n >= MIN_FOVS, sums.sum(axis=1) / n, np.nan)
        left = n[:, None] - counts
        replicate = (sums.sum(axis=1)[:, None] - sums) / left
    sigma = np.full(n_keys, np.nan)
    for i in np.flatnonzero(n >= MIN_FOVS):
        present = counts[i] > 0  # a group without FOVs of this key leaves the mean as it is
        r = replicate[i, present]
        m = r.size
        if m >= 2 and np.all(np.isfinite(r)):
            se = math.sqrt((m - 1) / m * float(np.sum((r - r.mean()) ** 2)))
            sigma[i] = se * t_factor(m - 1)
    return mean, sigma, n


def day_radiometry(matchup: Matchup, uniform: Uniformity, bands: tuple[str, ...]) -> DayRadiometry:
    """CrIS minus VIIRS per band and FOR, and by FOV, scene temperature and node, on the day's mapping.

    Parameters
    ----------
    matchup : Matchup
        The day's mapping, on the assessed geolocation.
    uniform : Uniformity
        The uniformity test.
    bands : tuple of str
        The bands compared, among those mapped.

    Returns
    -------
    DayRadiometry
        Per band mapped, its FORs' means and sigmas (K), and the bins.
    """
    shape = matchup.latitude_deg.shape  # (scans, 30, 9)
    group = np.broadcast_to(_groups(matchup)[:, None, None], shape)
    for_key = np.broadcast_to(np.arange(N_FOR)[None, :, None], shape)
    fov_key = np.broadcast_to(np.arange(N_FOV)[None, None, :], shape)
    node_key = np.broadcast_to(np.where(ascending(matchup), 0, 1)[:, None, None], shape)
    per_band, bins, maps = [], [], []
    granule = np.asarray(matchup.granule_of_scan)
    for b, band in enumerate(matchup.bands):
        if band not in bands:
            continue
        v = {name: matchup.values[name][b] for name in matchup.values}
        d = v["cris_bt_k"] - v["viirs_bt_k"]
        scene = v["viirs_bt_k"]
        with np.errstate(invalid="ignore"):
            keep = (
                np.isfinite(d)
                & (v["viirs_bt_std_k"] <= uniform.max_std_k)
                & (v["viirs_valid_fraction"] >= uniform.min_coverage)
            )
            if BANDS[band].min_scene_k is not None:
                keep &= scene > BANDS[band].min_scene_k
        mean, sigma, n = _jackknifed(d, keep, for_key, N_FOR, group)
        per_band.append(BandDifference(band, mean, sigma, n))
        if keep.any():
            g = int(np.argmax(np.bincount(granule[np.nonzero(keep)[0]], minlength=len(matchup.granules))))
            at = granule == g
            maps.append(
                DifferenceMap(
                    band,
                    matchup.granules[g],
                    matchup.latitude_deg[at],
                    matchup.longitude_deg[at],
                    d[at],
                    keep[at],
                )
            )
        scene_key = np.where(keep, np.floor(np.nan_to_num(scene) / SCENE_BIN_K), 0).astype(int)
        low = int(scene_key[keep].min()) if keep.any() else 0
        n_scene = int(scene_key[keep].max()) - low + 1 if keep.any() else 1
        scene_labels = [f"{(i + low) * SCENE_BIN_K:g}" for i in range(n_scene)]
        for by, key, labels in (
            (BinnedBy.FOV, fov_key, [str(i + 1) for i in range(N_FOV)]),
            (BinnedBy.SCENE, scene_key - low, scene_labels),
            (BinnedBy.NODE, node_key, ["ascending", "descending"]),
        ):
            m, s, c = _jackknifed(d, keep, np.where(keep, key, 0), len(labels), group)
            bins += [
                RadiometryBin(band, by, label, int(c[i]), float(m[i]), float(s[i]))
                for i, label in enumerate(labels)
                if c[i] > 0
            ]
    return DayRadiometry(tuple(per_band), tuple(bins), tuple(maps))


def with_radiometry(result: AssessmentResult, radiometry: DayRadiometry) -> AssessmentResult:
    """The day's *result* with its FORs' ``cris_minus_viirs_k_<BAND>`` and their sigmas, and its bins.

    Parameters
    ----------
    result : AssessmentResult
        The day's assessment.
    radiometry : DayRadiometry
        Its comparison (:func:`day_radiometry`).

    Returns
    -------
    AssessmentResult
        A copy carrying them, and the difference maps.
    """
    fors = []
    for k, f in enumerate(result.fors):
        values: dict[str, Any] = {}
        for band in radiometry.bands:
            values[f"cris_minus_viirs_k_{band.band}"] = float(band.mean_k[k])
            values[f"sigma_cris_minus_viirs_k_{band.band}"] = float(band.sigma_k[k])
        fors.append(replace(f, **values))
    return replace(result, fors=fors, radiometry=list(radiometry.bins), difference_maps=list(radiometry.maps))
