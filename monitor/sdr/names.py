"""JPSS file names:
``{PRODIDS}_{plat}_d{YYYYMMDD}_t{HHMMSSS}_e{HHMMSSS}_b{orbit}_c{created}_{origin}_{domain}.h5``.

The t/e fields are HHMMSS plus tenths of a second; the end may roll past midnight. An SDR and its GEO
file differ only in the creation time, so granules are paired on ``plat_d_t_e_b`` (docs/jpss-formats.md 1.1).
"""

from __future__ import annotations

import datetime as dt
import re
from collections.abc import Sequence
from dataclasses import dataclass

_PATTERN = re.compile(
    r"^(?P<products>[A-Z0-9]{5}(?:-[A-Z0-9]{5}){0,15})_(?P<platform>[a-z0-9]{3})_d(?P<date>\d{8})"
    r"_t(?P<start>\d{7})_e(?P<end>\d{7})_b(?P<orbit>\d{5,6})_c(?P<created>\d{20})_(?P<origin>[a-z0-9-]{4})"
    r"_(?P<domain>[a-z_]{1,16})\.h5$",
    re.ASCII,
)  # ASCII digits only: a key with other digits must not pass for a granule. Every field is bounded as
# the real names are (5-letter product IDs, 5-6 digit orbits): a longer name is no granule, nor cacheable.


@dataclass(frozen=True)
class JpssName:
    """The fields of a JPSS product file name."""

    products: tuple[str, ...]
    platform: str
    start: dt.datetime
    end: dt.datetime
    orbit: int
    created: str
    origin: str
    domain: str

    @property
    def granule_key(self) -> str:  # numpydoc ignore=RT01
        """``plat_dYYYYMMDD_tHHMMSSS_eHHMMSSS_bNNNNN``: identical for an SDR and its GEO file."""
        return (
            f"{self.platform}_d{self.start:%Y%m%d}_t{self.start:%H%M%S}{self.start.microsecond // 100000}"
            f"_e{self.end:%H%M%S}{self.end.microsecond // 100000}_b{self.orbit:05d}"
        )


def _clock(date: dt.date, hhmmsst: str) -> dt.datetime:
    return dt.datetime(
        date.year,
        date.month,
        date.day,
        int(hhmmsst[:2]),
        int(hhmmsst[2:4]),
        int(hhmmsst[4:6]),
        int(hhmmsst[6]) * 100000,
        tzinfo=dt.timezone.utc,
    )


def parse_name(name: str) -> JpssName | None:
    """The parsed name, or None if *name* (a base name) is not a JPSS product file name (an impossible
    date or time included).

    Parameters
    ----------
    name : str
        A file's base name.

    Returns
    -------
    JpssName or None
        Its fields; None for another name.
    """
    m = _PATTERN.match(name)
    if not m:
        return None
    try:
        date = dt.datetime.strptime(m["date"], "%Y%m%d").date()
        start = _clock(date, m["start"])
        end = _clock(date, m["end"])
    except ValueError:
        return None
    if end < start:
        end += dt.timedelta(days=1)
    return JpssName(
        tuple(m["products"].split("-")),
        m["platform"],
        start,
        end,
        int(m["orbit"]),
        m["created"],
        m["origin"],
        m["domain"],
    )


def format_name(
    products: Sequence[str],
    platform: str,
    start: dt.datetime,
    end: dt.datetime,
    orbit: int,
    created: dt.datetime,
    origin: str = "oebc",
    domain: str = "ops",
) -> str:
    """A JPSS file name for the given fields (used by the simulator).

    Parameters
    ----------
    products : sequence of str
        The product prefixes.
    platform : str
        ``npp``, ``j01``, ``j02``.
    start, end : datetime.datetime
        The granule's span, UTC.
    orbit : int
        The orbit number.
    created : datetime.datetime
        The creation time, UTC.
    origin : str, optional
        The origin field.
    domain : str, optional
        The domain field.

    Returns
    -------
    str
        The file name.
    """

    def clock(t: dt.datetime) -> str:
        return f"{t:%H%M%S}{t.microsecond // 100000}"

    return (
        f"{'-'.join(products)}_{platform}_d{start:%Y%m%d}_t{clock(start)}_e{clock(end)}_b{orbit:05d}"
        f"_c{created:%Y%m%d%H%M%S%f}_{origin}_{domain}.h5"
    )
