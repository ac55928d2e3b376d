"""The day's mapping: the CrIS granules a day assessed, mapped onto the configured VIIRS bands on the
day's own offsets (``assessment.bands``, and ``mapping_bands`` where ``mapping_dir`` is set;
:mod:`monitor.matchup`), and the day's CrIS minus VIIRS per band read from it
(:mod:`monitor.matchup.radiometry`).

The I5 granules are those the assessment fetched; each other band's granules are listed from the source
and fetched for the same VIIRS granules (an M-band file shares its I-band file's
``platform_date_start_end_orbit`` key): read in place from NODD, only the datasets the mapping reads travel.
A granule that cannot be had is a note in the mapping, never the day's failure.
"""

from __future__ import annotations

import datetime as dt
import logging
from collections.abc import Callable

from monitor.archive import ListedFile, Source, SourceError, band_products
from monitor.config.assessment import AssessmentConfig
from monitor.core.errors import DataError
from monitor.core.result import AssessmentResult
from monitor.matchup import Matchup, map_plan
from monitor.matchup.radiometry import Uniformity, day_radiometry, with_radiometry
from monitor.sdr.pairing import CasePlan, GranuleFiles, granule_files
from monitor.sdr.products import prefixes

LOG = logging.getLogger(__name__)


def _band_granules(
    source: Source, listing: list[ListedFile], band: str, keys: set[str], skipped: list[tuple[str, str]]
) -> list[GranuleFiles]:
    """The band's granules of *keys* (VIIRS granule keys), fetched; what cannot be had joins *skipped*."""
    sdrs = {f.parsed.granule_key: f for f in listing if f.product in prefixes("viirs_sdr", band)}
    geo_order = prefixes("viirs_geo", band)
    geos: dict[str, ListedFile] = {}
    for f in sorted(listing, key=lambda f: geo_order.index(f.product) if f.product in geo_order else 99):
        if f.product in geo_order:
            geos.setdefault(f.parsed.granule_key, f)
    out = []
    for key in sorted(keys):
        if key not in sdrs or key not in geos:
            skipped.append((key, f"no {band} granule with its geolocation in the source"))
            continue
        try:
            out.append(granule_files(key, source.fetch(sdrs[key]), source.fetch(geos[key])))
        except (SourceError, DataError) as exc:
            skipped.append((key, f"{band}: {exc}"))
    return sorted(out, key=lambda g: g.start)


def band_plan(
    source: Source,
    satellite: str,
    day: dt.date,
    cases: list[CasePlan],
    bands: tuple[str, ...],
) -> CasePlan:
    """The day's assessed CrIS granules with their I5 granules and, fetched, each other band's.

    Parameters
    ----------
    source : Source
        Where the day's granules come from.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    cases : list of CasePlan
        The day's batches as the assessment fetched them.
    bands : tuple of str
        The VIIRS bands.

    Returns
    -------
    CasePlan
        The plan; a band granule that cannot be had is in its ``skipped``.
    """
    skipped: list[tuple[str, str]] = []
    cris = sorted({g.key: g for c in cases for g in c.cris}.values(), key=lambda g: g.start)
    viirs = sorted({g.key: g for c in cases for g in c.viirs_all}.values(), key=lambda g: g.start)
    plan = CasePlan(satellite, cris=cris, viirs_all=viirs, skipped=skipped, cris_all=cris)
    others = [b for b in bands if b != "I5"]
    if others:
        wanted = tuple(p for b in others for p in band_products(b))
        listing = source.list_day(satellite, day, wanted)
        keys = {g.key for g in viirs}
        for band in others:
            plan.bands[band] = _band_granules(source, listing, band, keys, skipped)
    return plan


def map_day(
    plan: CasePlan,
    result: AssessmentResult,
    bands: tuple[str, ...],
    should_stop: Callable[[], bool] | None = None,
) -> Matchup:
    """Map the day's assessed CrIS granules onto *bands*, on the day's offsets and fitted response.

    Parameters
    ----------
    plan : CasePlan
        The day's granules in every band (:func:`band_plan`).
    result : AssessmentResult
        The day's estimate.
    bands : tuple of str
        The VIIRS bands.
    should_stop : callable, optional
        Polled between granules.

    Returns
    -------
    Matchup
        The day's mapping.
    """
    matchup, cost = map_plan(plan, bands, result, should_stop)
    LOG.info(
        "mapped %d CrIS granule(s) onto %s: %.1f CPU-s reading, %.1f CPU-s mapping",
        len(plan.cris), ", ".join(bands), sum(cost.read_s.values()), sum(cost.map_s.values()),
    )  # fmt: skip
    return matchup


def with_bands(result: AssessmentResult, matchup: Matchup, cfg: AssessmentConfig) -> AssessmentResult:
    """The day's *result* with CrIS minus VIIRS in each of ``assessment.bands``, read from its mapping.

    Parameters
    ----------
    result : AssessmentResult
        The day's assessment.
    matchup : Matchup
        Its granules mapped on its offsets, in (at least) the configured bands.
    cfg : AssessmentConfig
        The assessment's configuration (``bands``, ``uniform_std_k``, ``min_coverage``).

    Returns
    -------
    AssessmentResult
        A copy with ``cris_minus_viirs_k_<BAND>`` and its sigma per FOR, and the bins.
    """
    uniform = Uniformity(cfg.uniform_std_k, cfg.min_coverage)
    return with_radiometry(result, day_radiometry(matchup, uniform, tuple(cfg.bands)))
