"""The argparse types of crisgeo's options: times, days, durations, counts, longitudes (a bad value is
argparse's one-line error, exit status 2)."""

from __future__ import annotations

import argparse
import datetime as dt
import re
from collections.abc import Callable

from nagiosplugin import Range


def iso_time(text: str) -> dt.datetime:
    try:
        when = dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an ISO 8601 time: {text!r}") from None
    return when if when.tzinfo else when.replace(tzinfo=dt.timezone.utc)


def until(text: str) -> dt.datetime:
    """An end: ISO 8601 (UTC unless it says), or a duration from now, ``12h`` or ``7d``.

    Parameters
    ----------
    text : str
        The argument.

    Returns
    -------
    datetime.datetime
        Aware, UTC; an argparse error otherwise.
    """
    m = re.fullmatch(r"(\d{1,4})([hd])", text.strip())
    if m:
        hours = int(m[1]) * (24 if m[2] == "d" else 1)
        return dt.datetime.now(dt.timezone.utc).replace(microsecond=0) + dt.timedelta(hours=hours)
    try:
        return iso_time(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"not an ISO 8601 time nor a duration (12h, 7d): {text!r}") from None


def iso_day(text: str) -> dt.date:
    try:
        return dt.date.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a date (YYYY-MM-DD): {text!r}") from None


def whole(least: int) -> Callable[[str], int]:
    """The argparse type of a whole number of at least *least* (a count of granules or processes, a seed).

    Parameters
    ----------
    least : int
        The least value.

    Returns
    -------
    callable
        The type.
    """

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
        if n < least:
            raise argparse.ArgumentTypeError(f"{n}: at least {least}")
        return n

    return parse


def longitude(text: str) -> float:
    """A longitude in degrees, -180..180.

    Parameters
    ----------
    text : str
        The argument.

    Returns
    -------
    float
        deg.
    """
    try:
        lon = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not -180.0 <= lon <= 180.0:  # NaN fails too
        raise argparse.ArgumentTypeError(f"{text}: not a longitude within -180..180 deg")
    return lon


def nagios_range(text: str) -> Range:
    """A monitoring-plugins threshold range: ``10`` (alert outside 0..10), ``10:`` (below 10), ``~:10``
    (above 10), ``10:20`` (outside), ``@10:20`` (inside).

    Parameters
    ----------
    text : str
        The argument.

    Returns
    -------
    Range
        The range.
    """
    try:
        return Range(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"not a threshold range (10, 10:, ~:10, 10:20, @10:20): {text!r}"
        ) from None


def band_list(text: str) -> tuple[str, ...]:
    """VIIRS bands, comma-separated: ``I5,M15,M16,M13`` (any order and case).

    Parameters
    ----------
    text : str
        The argument.

    Returns
    -------
    tuple of str
        The bands in the band table's order; an argparse error otherwise.
    """
    from monitor.core.bands import parse_bands
    from monitor.core.errors import DataError

    try:
        return parse_bands(text)
    except DataError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def band_values_k(text: str) -> dict[str, float]:
    """A value in K per VIIRS band: ``M15=0.15,M16=-0.1``.

    Parameters
    ----------
    text : str
        The argument.

    Returns
    -------
    dict
        Band to K; an argparse error otherwise.
    """
    out: dict[str, float] = {}
    for item in filter(None, (t.strip() for t in text.split(","))):
        band, eq, value = item.partition("=")
        try:
            (name,) = band_list(band)
            out[name] = float(value)
        except (ValueError, argparse.ArgumentTypeError):
            raise argparse.ArgumentTypeError(
                f"{item!r} is not BAND=K (a band of I5, M13, M15, M16 and a number of kelvin)"
            ) from None
        if not eq or not -10.0 <= out[name] <= 10.0:
            raise argparse.ArgumentTypeError(f"{item!r}: the value must be a number of kelvin within +-10")
    if not out:
        raise argparse.ArgumentTypeError(f"{text!r}: no BAND=K given")
    return out


def satellite_name(text: str) -> str:
    """A satellite as users write it (``noaa20``, ``n20``, ``j01``, ``snpp``, ``NOAA-21`` ...).

    Parameters
    ----------
    text : str
        The argument.

    Returns
    -------
    str
        The short name (npp, j01, j02); an argparse error otherwise.
    """
    from monitor.core.errors import DataError
    from monitor.core.satellites import named

    try:
        return named(text)
    except DataError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
