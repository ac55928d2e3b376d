"""The alert rules of CrIS minus VIIRS per band (:mod:`monitor.matchup.radiometry`): a band's level beyond
``radiometry_limit_k``, the calibration-jump rule's watch of each band, and whose a band's step is, told
from the bands that moved with it."""

from __future__ import annotations

import datetime as dt

import numpy as np

from alerts.rules import CHANGED, Finding, Watched
from monitor.config.alert_settings import RuleSettings
from monitor.core.bands import BANDS
from monitor.core.vocabulary import Rule, Severity
from monitor.history.records import History


def band_watch(band: str) -> Watched:
    """The calibration-jump rule's watch of one band's daily CrIS minus VIIRS difference
    (``cris_minus_viirs_k_<BAND>``, :mod:`monitor.matchup.radiometry`).

    Parameters
    ----------
    band : str
        The VIIRS band.

    Returns
    -------
    Watched
        The quantity.
    """
    return Watched(
        Rule.CALIBRATION_JUMP,
        f"CrIS-VIIRS {band}",
        (f"cris_minus_viirs_k_{band}",),
        (f"sigma_cris_minus_viirs_k_{band}",),
        (band,),
        "K",
        "min_bias_jump_k",
        3,
        band,
    )


BAND_WATCHES = tuple(band_watch(b) for b in BANDS)


def radiometry_finding(store: History, satellite: str, s: RuleSettings) -> Finding | None:
    """FORs of the latest day whose CrIS minus VIIRS difference in a band is beyond ``radiometry_limit_k``
    in magnitude: paged as the specification is, critical where every such difference is beyond the limit
    by 2 sigma, warning otherwise.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    s : RuleSettings
        The rules' parameters.

    Returns
    -------
    Finding or None
        None where every band is within the limit (or none was measured).
    """
    day = store.latest_day(satellite)
    if day is None:
        return None
    limit = s.radiometry_limit_k
    rows = []
    for f in store.day_result(satellite, day):
        for band in BANDS:
            d, sig = getattr(f, f"cris_minus_viirs_k_{band}"), getattr(f, f"sigma_cris_minus_viirs_k_{band}")
            if np.isfinite(d) and abs(d) > limit:
                rows.append((band, f.for_index, d, sig, bool(np.isfinite(sig) and abs(d) - 2 * sig > limit)))
    if not rows:
        return None
    bands = sorted({r[0] for r in rows}, key=list(BANDS).index)
    lines = [
        f"{band} FOR {k:2d}: CrIS minus VIIRS {d:+.3f} +- {sig:.3f} K (limit {limit:g} K)"
        + ("" if sure else " (within 2 sigma of the limit)")
        for band, k, d, sig, sure in rows
    ]
    return Finding(
        Rule.RADIOMETRY,
        satellite,
        Severity.CRITICAL if all(r[4] for r in rows) else Severity.WARNING,
        f"{satellite}: CrIS minus VIIRS beyond {limit:g} K on {day} in {', '.join(bands)} "
        f"({len(rows)} FOR-band(s))",
        lines,
        data={"day": day.isoformat(), "bands": bands, "fors": sorted({r[1] for r in rows})},
    )


def attribute_bands(
    band_steps: list[Finding], geolocation_steps: list[Finding], measured: set[str], s: RuleSettings
) -> None:
    """Tell each band's calibration step whose it is from what moved with it, in place.

    A change of CrIS's calibration moves every band of its spectral band alike (I5, M15 and M16 lie in
    its long-wave band, M13 in its short-wave one); a VIIRS band's calibration moves that band alone; a
    geolocation change moves the offsets. A step in one band of several measured, without a geolocation
    step within ``attribution_days``, is VIIRS's; a step in every measured band of one CrIS band is CrIS's
    (or common to VIIRS's bands). The evidence is a line and ``data["evidence"]``; a known change from
    the calendar stays the finding's named cause.

    Parameters
    ----------
    band_steps : list of Finding
        The calibration-jump findings of the bands (:data:`BAND_WATCHES`).
    geolocation_steps : list of Finding
        The geolocation jump findings of the same satellite.
    measured : set of str
        The bands with differences in the history.
    s : RuleSettings
        The rules' parameters.
    """

    def near(a: Finding, b: Finding) -> bool:
        gap = dt.date.fromisoformat(a.data["split"]) - dt.date.fromisoformat(b.data["split"])
        return abs(gap.days) <= s.attribution_days

    for f in band_steps:
        band = f.data["band"]
        moved = {g.data["band"] for g in band_steps if near(f, g)}
        kin = {b for b in measured if BANDS[b].cris_band == BANDS[band].cris_band}
        geo = any(near(f, g) for g in geolocation_steps)
        if moved == {band} and len(measured) > 1 and not geo:
            evidence = "viirs"
            line = (
                f"evidence: only {band} moved of {', '.join(sorted(measured))}, and the CrIS geolocation did "
                f"not: VIIRS {band}'s calibration (a CrIS change moves every band of its spectral band)"
            )
        elif len(kin) > 1 and kin <= moved:
            evidence = "cris"
            line = (
                f"evidence: every measured band of CrIS's {BANDS[band].cris_band} band moved "
                f"({', '.join(sorted(kin))}): CrIS's calibration, or a change common to VIIRS's bands"
            )
        else:
            evidence, line = None, f"evidence: {', '.join(sorted(moved))} moved; not told apart"
        if geo:
            line += "; the CrIS geolocation moved too"
        f.lines.insert(2, line)
        f.data["evidence"] = evidence
        if evidence and f.data.get("change") is None:
            f.summary = f.summary.replace(
                "(no known change)", f"(no known change; by its bands {CHANGED[evidence]}'s)"
            )
