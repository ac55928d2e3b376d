"""IDPS Epoch Time (IET): microseconds since 1958-01-01T00:00:00 counting TAI seconds.

Converting to UTC needs the leap seconds (TAI - UTC); treating IET as naive UTC is wrong by 34-37 s
(docs/jpss-formats.md 1.6). Times before 1972 are outside JPSS and not supported.
"""

from __future__ import annotations

import datetime as dt

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.errors import DataError

UTC = dt.timezone.utc
IET_EPOCH = dt.datetime(1958, 1, 1, tzinfo=UTC)
_UNIX_MINUS_IET_EPOCH_US = int((dt.datetime(1970, 1, 1, tzinfo=UTC) - IET_EPOCH).total_seconds()) * 1_000_000

# (UTC date from which it holds, TAI - UTC in seconds); IERS Bulletin C.
LEAP_SECONDS = (
    ((1972, 1, 1), 10),
    ((1972, 7, 1), 11),
    ((1973, 1, 1), 12),
    ((1974, 1, 1), 13),
    ((1975, 1, 1), 14),
    ((1976, 1, 1), 15),
    ((1977, 1, 1), 16),
    ((1978, 1, 1), 17),
    ((1979, 1, 1), 18),
    ((1980, 1, 1), 19),
    ((1981, 7, 1), 20),
    ((1982, 7, 1), 21),
    ((1983, 7, 1), 22),
    ((1985, 7, 1), 23),
    ((1988, 1, 1), 24),
    ((1990, 1, 1), 25),
    ((1991, 1, 1), 26),
    ((1992, 7, 1), 27),
    ((1993, 7, 1), 28),
    ((1994, 7, 1), 29),
    ((1996, 1, 1), 30),
    ((1997, 7, 1), 31),
    ((1999, 1, 1), 32),
    ((2006, 1, 1), 33),
    ((2009, 1, 1), 34),
    ((2012, 7, 1), 35),
    ((2015, 7, 1), 36),
    ((2017, 1, 1), 37),
)
_CHANGE_UNIX_US = np.array(
    [int(dt.datetime(*d, tzinfo=UTC).timestamp()) * 1_000_000 for d, _ in LEAP_SECONDS]
)
_OFFSET_US = np.array([s * 1_000_000 for _, s in LEAP_SECONDS], dtype=np.int64)
_CHANGE_IET_US = _CHANGE_UNIX_US + _UNIX_MINUS_IET_EPOCH_US + _OFFSET_US


def iet_to_unix_us(iet_us: ArrayLike) -> np.ndarray:
    """UTC microseconds since 1970 (int64) of IET microseconds.

    Parameters
    ----------
    iet_us : array_like
        IET, us since 1958-01-01 counting TAI seconds.

    Returns
    -------
    numpy.ndarray
        Unix time, us.
    """
    iet = np.asarray(iet_us, np.int64)
    k = np.searchsorted(_CHANGE_IET_US, iet, side="right") - 1
    if np.any(k < 0):
        raise DataError(f"IET {int(np.min(iet))} is before 1972, outside the leap-second table")
    return iet - _UNIX_MINUS_IET_EPOCH_US - _OFFSET_US[k]


def unix_us_to_iet(unix_us: ArrayLike) -> np.ndarray:
    """IET microseconds (int64) of UTC microseconds since 1970.

    Parameters
    ----------
    unix_us : array_like
        Unix time, us.

    Returns
    -------
    numpy.ndarray
        IET, us.
    """
    u = np.asarray(unix_us, np.int64)
    k = np.searchsorted(_CHANGE_UNIX_US, u, side="right") - 1
    if np.any(k < 0):
        raise DataError("UTC time before 1972 is outside the leap-second table")
    return u + _UNIX_MINUS_IET_EPOCH_US + _OFFSET_US[k]


def iet_to_datetime(iet_us: ArrayLike) -> dt.datetime:
    """Timezone-aware UTC datetime of one IET value.

    Parameters
    ----------
    iet_us : int
        IET, us.

    Returns
    -------
    datetime.datetime
        UTC.
    """
    return dt.datetime(1970, 1, 1, tzinfo=UTC) + dt.timedelta(microseconds=int(iet_to_unix_us(iet_us)))


def datetime_to_iet(when: dt.datetime) -> int:
    """IET microseconds of a timezone-aware datetime.

    Parameters
    ----------
    when : datetime.datetime
        A UTC time.

    Returns
    -------
    int
        IET, us.
    """
    delta = when.astimezone(UTC) - dt.datetime(1970, 1, 1, tzinfo=UTC)
    return int(unix_us_to_iet((delta.days * 86400 + delta.seconds) * 1_000_000 + delta.microseconds))
