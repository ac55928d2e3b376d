"""Where granules come from: a local directory tree, NOAA's NODD buckets over HTTPS, or the simulator.

A source lists the files of one satellite-day by product and fetches a listed file to a local path.
It knows file names and transport, nothing of the science.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Protocol

from monitor.sdr.granules import GranuleRef
from monitor.sdr.names import JpssName, parse_name
from monitor.sdr.products import CRIS_PRODUCTS, VIIRS_GEO, VIIRS_SDR, prefixes

ALL_PRODUCTS = CRIS_PRODUCTS + VIIRS_SDR + VIIRS_GEO  # what the assessment lists: CrIS, VIIRS I5


def band_products(band: str) -> tuple[str, ...]:
    """The products a VIIRS band needs listed: its SDR and its grid's geolocation.

    Parameters
    ----------
    band : str
        I5, M13, M15 or M16.

    Returns
    -------
    tuple of str
        Product prefixes, the preferred first of each kind.
    """
    return prefixes("viirs_sdr", band) + prefixes("viirs_geo", band)


class SourceError(RuntimeError):
    """A listing or a download failed after its retries."""


class BudgetExceeded(SourceError):
    """The day's download budget is spent."""


@dataclass(frozen=True)
class ListedFile:
    """A granule file a source can fetch: its name, size in bytes (None if unknown), location and, where the
    listing gives one, the MD5 of its content (hex)."""

    name: str
    size: int | None
    location: str
    parsed: JpssName
    md5: str | None = None

    @property
    def product(self) -> str:  # numpydoc ignore=RT01
        """The file's (first) product prefix, e.g. GCRSO."""
        return self.parsed.products[0]


def listed(name: str, size: int | None, location: str, md5: str | None = None) -> ListedFile | None:
    """A :class:`ListedFile` for a safe JPSS file name (a base name, so no dot segment can slip in), or
    None for anything else (path parts, non-ASCII, odd names).

    Parameters
    ----------
    name : str
        The file's base name.
    size : int or None
        Its size, bytes.
    location : str
        Where it is (a path or a key).
    md5 : str, optional
        Its checksum as the archive lists it.

    Returns
    -------
    ListedFile or None
        None for anything but a safe JPSS file name.
    """
    if not name.isascii() or "/" in name or "\\" in name or name.startswith("."):
        return None
    parsed = parse_name(name)
    return None if parsed is None else ListedFile(name, size, location, parsed, md5)


def on_day(f: ListedFile, day: dt.date) -> bool:
    """Whether *f* starts on *day* (UTC).

    Parameters
    ----------
    f : ListedFile
        A listed file.
    day : datetime.date
        The UTC day.

    Returns
    -------
    bool
        Whether the file starts on the day.
    """
    return f.parsed.start.date() == day


class Source(Protocol):
    """What the daily run needs of a source (local tree, simulator, NODD)."""

    spent_bytes: int  # downloaded in this run (whole files and ranges)
    downloaded_files: int  # downloaded whole in this run
    requests: int  # HTTP requests sent in this run

    def start_day(self, should_stop: Callable[[], bool] | None = None) -> None:
        """Start a run: reset the run's budget and deadline, apply the cache retention; *should_stop*, the
        run's stop request, is polled between the long steps of listing (a :class:`StopRequested`).

        Parameters
        ----------
        should_stop : callable, optional
            The run's stop request, polled between the long steps.
        """

    def list_day(self, satellite: str, day: dt.date, products: Iterable[str]) -> list[ListedFile]:
        """The granule files of *satellite* for *day* whose product is in *products*.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        products : iterable of str
            The product prefixes wanted (GCRSO, SCRIF, SVI05, GITCO, ...).
        """

    def fetch(self, f: ListedFile) -> GranuleRef:
        """*f* to read: a local path holding it (downloaded if need be), or a granule read in place;
        :class:`SourceError` on failure.

        Parameters
        ----------
        f : ListedFile
            A listed file.
        """
