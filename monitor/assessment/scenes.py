"""Scene selection: the day's CrIS granules whose scenes are inhomogeneous enough to pin the geolocation.

Candidates are spread evenly over the day; only the small CrIS files are fetched to score them. The
score is the inhomogeneity of the CrIS I5-equivalent brightness temperature at the FOV scale: the mean,
over the granule's FORs, of the standard deviation of the 9 FOV BTs (K). Clouds over ocean and
coastlines score high; uniform scenes carry no information and score near the noise. Granules
without VIIRS I5 and GEO coverage in the listing are skipped before anything is fetched. The usable ones
are ranked by information per byte (:func:`bytes_of`), the order in which the daily run assesses them in
batches (:func:`monitor.assessment.day.assess_in_batches`). Every candidate gets a decision and its reason.
"""

from __future__ import annotations

import datetime as dt
import logging
import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from monitor.archive import BudgetExceeded, ListedFile, Source, SourceError
from monitor.core.errors import DataError
from monitor.core.result import SceneDecision
from monitor.core.vocabulary import Decision
from monitor.instrument.spectral import i5_band
from monitor.sdr import GranuleError, read_file
from monitor.sdr.pairing import GranuleFiles, granule_files
from monitor.sdr.products import CRIS_GEO, CRIS_SDR, VIIRS_GEO, VIIRS_SDR

LOG = logging.getLogger(__name__)
COVER_MARGIN = dt.timedelta(seconds=10)


@dataclass
class Candidate:
    """A CrIS granule considered: its listed SDR and GEO, the listed VIIRS pairs covering it, its score (K)
    and, once fetched and read, its :class:`monitor.sdr.pairing.GranuleFiles` (paths and metadata)."""

    key: str
    sdr: ListedFile
    geo: ListedFile
    viirs: list  # [(sdr, geo)] listed VIIRS pairs covering it
    score_k: float = float("nan")
    files: GranuleFiles | None = None


def _pairs(
    files: list[ListedFile], sdr_prefixes: Iterable[str], geo_prefixes: Iterable[str]
) -> tuple[list[tuple[str, ListedFile, ListedFile]], list[str]]:
    sdr = {f.parsed.granule_key: f for f in files if f.product in sdr_prefixes}
    geo = {f.parsed.granule_key: f for f in files if f.product in geo_prefixes}
    both = sorted(set(sdr) & set(geo), key=lambda k: geo[k].parsed.start)
    single = sorted(set(sdr) ^ set(geo))
    return [(k, sdr[k], geo[k]) for k in both], single


def inhomogeneity_k(radiance_lw: np.ndarray, satellite: str) -> float:
    """The mean over FORs of the standard deviation of the 9 FOVs' I5-equivalent BT.

    Parameters
    ----------
    radiance_lw : numpy.ndarray
        The granule's CrIS LW spectra, mW/(m2 sr cm-1).
    satellite : str
        The satellite's short name (its I5 band).

    Returns
    -------
    float
        K.
    """
    band = i5_band(satellite)
    bt = band.bt_from_radiance(band.cris_band_radiance(radiance_lw))
    return float(np.nanmean(np.nanstd(bt, axis=-1)))


def rank_scenes(
    listing: list[ListedFile], source: Source, satellite: str, candidates: int, min_score_k: float
) -> tuple[list[Candidate], list[SceneDecision]]:
    """The usable candidates of a day's listing, the most informative per byte first.

    Scoring reads each candidate's CrIS SDR and GEO files (a few MB); no VIIRS byte is read before a candidate
    is assessed.

    Parameters
    ----------
    listing : list of ListedFile
        The day's listing.
    source : Source
        Where the CrIS files are read from.
    satellite : str
        The satellite's short name.
    candidates : int
        How many CrIS granules to score, spread over the day.
    min_score_k : float
        The least inhomogeneity a candidate must have, K.

    Returns
    -------
    candidates : list of Candidate
        The usable ones, ranked.
    decisions : list of SceneDecision
        Every other granule of the listing, rejected or not considered, with the reason.
    """
    decisions: list[SceneDecision] = []
    cris, unpaired = _pairs(listing, CRIS_SDR, CRIS_GEO)
    for key in unpaired:
        decisions.append(SceneDecision(key, Decision.REJECTED, "SDR or GEO file missing in the listing"))
    viirs, _ = _pairs(listing, VIIRS_SDR, VIIRS_GEO)
    if len(cris) > candidates:
        picks = set(np.round(np.linspace(0, len(cris) - 1, candidates)).astype(int))
        for i, (key, _, _) in enumerate(cris):
            if i not in picks:
                decisions.append(
                    SceneDecision(
                        key,
                        Decision.NOT_CONSIDERED,
                        f"outside the {candidates} candidates spread over the day",
                    )
                )
        cris = [c for i, c in enumerate(cris) if i in picks]
    pool = []
    for key, sdr, geo in cris:
        start, end = geo.parsed.start, geo.parsed.end
        cover = [
            (vs, vg)
            for _, vs, vg in viirs
            if vg.parsed.start <= end + COVER_MARGIN and vg.parsed.end >= start - COVER_MARGIN
        ]
        if not cover:
            decisions.append(SceneDecision(key, Decision.REJECTED, "no VIIRS I5 + GEO granule covers it"))
            continue
        try:
            sdr_path, geo_path = source.fetch(sdr), source.fetch(geo)
            granules = read_file(sdr_path, kinds=("cris_sdr",))
            if len(granules) != 1:
                raise GranuleError(sdr_path, "(file)", f"holds {len(granules)} granules; one is expected")
            (granule,) = granules
            files = granule_files(key, sdr_path, geo_path, sdr_meta=granule.meta)
            score = inhomogeneity_k(np.where(granule.good[..., None], granule.radiance_lw, np.nan), satellite)
        except BudgetExceeded as exc:
            decisions.append(SceneDecision(key, Decision.REJECTED, str(exc)))
            break
        except (SourceError, DataError) as exc:
            decisions.append(SceneDecision(key, Decision.REJECTED, f"unusable CrIS granule: {exc}"))
            continue
        pool.append(Candidate(key, sdr, geo, cover, score, files))
    ranked = []
    for c in pool:
        if np.isfinite(c.score_k) and c.score_k >= min_score_k:
            ranked.append(c)
        else:
            decisions.append(
                SceneDecision(
                    c.key,
                    Decision.REJECTED,
                    f"too homogeneous ({c.score_k:.2f} K < {min_score_k} K)",
                    c.score_k,
                )
            )
    covering = Counter(vg.parsed.granule_key for c in ranked for _, vg in c.viirs)
    return sorted(ranked, key=lambda c: -c.score_k / max(1.0, bytes_of(c, covering))), decisions


def bytes_of(c: Candidate, covering: Counter[str]) -> float:
    """What assessing a candidate costs in bytes, as listed.

    A VIIRS granule that two consecutive CrIS granules share costs each half, so at equal information per
    byte consecutive runs come first.

    Parameters
    ----------
    c : Candidate
        The candidate.
    covering : Counter of str
        Per VIIRS granule key, how many candidates it covers.

    Returns
    -------
    float
        Its CrIS SDR and GEO and its share of each VIIRS pair covering it, bytes.
    """
    own = (c.sdr.size or 0) + (c.geo.size or 0)
    return own + sum(
        ((vs.size or 0) + (vg.size or 0)) / covering[vg.parsed.granule_key] for vs, vg in c.viirs
    )


def next_batch(taken: int, sigma_urad: float | None, target_urad: float, keep: int) -> int:
    """How many granules the next batch takes.

    The estimate is made again after each batch and grows with the day, so batches that grow with it keep a
    long day's estimates linear in its granules; the ranking puts the most informative granules first, so the
    sigma falls more slowly than 1 / sqrt(N) and the aim falls short rather than beyond.

    Parameters
    ----------
    taken : int
        The granules assessed so far.
    sigma_urad : float or None
        The day's sigma they give, urad (None: not estimable yet).
    target_urad : float
        ``scenes.target_sigma_urad``.
    keep : int
        ``scenes.keep``: the fewest of a batch.

    Returns
    -------
    int
        taken (sigma / target)^2 - taken, at least *keep* and at most *taken* (the day at most doubles).
    """
    if sigma_urad is None or taken == 0:
        return keep
    needed = math.ceil(taken * (sigma_urad / target_urad) ** 2 - 1e-9) - taken
    return max(keep, min(needed, taken))


def batch_decisions(ranked: list[Candidate], sizes: list[int], why_not: str) -> list[SceneDecision]:
    """The decisions of the ranked candidates once a day has assessed its first ones in batches.

    Parameters
    ----------
    ranked : list of Candidate
        The candidates, ranked.
    sizes : list of int
        The batches' sizes.
    why_not : str
        Why the day stopped: the reason of those not assessed.

    Returns
    -------
    list of SceneDecision
        Chosen with their rank and batch, the rest rejected.
    """
    batch_of = np.repeat(np.arange(1, len(sizes) + 1), sizes)
    return [
        SceneDecision(
            c.key,
            Decision.CHOSEN,
            f"inhomogeneity {c.score_k:.2f} K, rank {i + 1}, batch {batch_of[i]}",
            c.score_k,
        )
        if i < len(batch_of)
        else SceneDecision(c.key, Decision.REJECTED, f"not assessed: {why_not}", c.score_k)
        for i, c in enumerate(ranked)
    ]
