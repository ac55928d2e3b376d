"""The JPSS satellites the monitor knows: one table, from which names, buckets and orbits are derived.

Orbits (mean elements of a circular sun-synchronous orbit, ascending node at 13:30 local solar time):
S-NPP mean altitude 838.8 km and inclination 98.67 deg (Lin et al. 2016, "Trending of SNPP ephemeris and
its implications on VIIRS geometric performance", drag make-up and inclination maneuvers keep them);
NOAA-21 833 km, 98.8 deg (NASA mission facts); NOAA-20 flies the same orbit. Phasing as flown since the
NOAA-20 rephasing of April 2024: NOAA-21 a quarter orbit ahead of S-NPP, NOAA-20 directly opposite
NOAA-21 (a quarter orbit behind S-NPP). The phase reference itself (S-NPP at the ascending node at
``PHASE_EPOCH_UNIX_S``, advancing with the shared ``NODAL_PERIOD_S``) is illustrative: the simulator needs
consistent, not operational, ephemerides.

Launch times (UTC, the day's orbit count starts there): S-NPP 2011-10-28 09:48:01, NOAA-20 2017-11-18
09:47:36, NOAA-21 2022-11-10 09:49:25 (NASA/NOAA mission pages). A granule's orbit number is the orbits
flown since launch; checked on real names: NOAA-20 b04790 on 2018-10-22 00:24 (4790.0 from this table),
S-NPP b25538 on 2016-10-01 09:30 (25537.8).
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

from monitor.core.errors import DataError


@dataclass(frozen=True)
class Satellite:
    """One satellite: file-name platform, IDPS platform name, long name, NODD bucket and mean orbit."""

    short: str  # platform in JPSS file names: npp, j01, j02
    idps: str  # HDF5 Platform_Short_Name
    name: str  # the name people use
    bucket: str  # NOAA Open Data Dissemination (NODD) bucket
    altitude_m: float  # mean altitude above the equatorial radius
    inclination_deg: float
    ltan_h: float  # local solar time of the ascending node, hours
    phase_deg: float  # mean argument of latitude ahead of S-NPP
    launch_unix_s: float  # launch, UTC seconds since 1970
    mission: str  # HDF5 Mission_Name of its granules
    srf_platform: str  # whose VIIRS spectral responses, monitor/data/srf (NOAA-21 has none public: NOAA-20's)
    ep_file: str | None  # the real CrIS engineering packet shipped, monitor/data/ep
    cris_instrument_id: int | None  # InstrumentId of its CrIS in EP XML files
    pct_mounting_urad: tuple[float, float, float] | None  # CrIS PCT mounting roll, pitch, yaw (LW-GEO)

    def orbit_number(self, unix_s: float) -> int:
        """The orbit number IDPS gives a granule starting at a time: whole orbits since launch, plus one.

        Parameters
        ----------
        unix_s : float
            The granule's start, Unix s.

        Returns
        -------
        int
            The orbit number.
        """
        return int((unix_s - self.launch_unix_s) // NODAL_PERIOD_S) + 1

    @property
    def launch_day(self) -> dt.date:  # numpydoc ignore=RT01
        """The UTC day of the launch."""
        return dt.datetime.fromtimestamp(self.launch_unix_s, dt.timezone.utc).date()

    @property
    def aliases(self) -> tuple[str, ...]:  # numpydoc ignore=RT01
        """The names users write for it, lower case: its platform (j01), its name (noaa20) and its NODD
        bucket's (n20)."""
        return tuple(
            dict.fromkeys((self.short, self.idps.lower(), _folded(self.name), self.bucket.split("-")[2]))
        )

    def outside_mission(self, day: dt.date, today: dt.date) -> str | None:
        """Why a day can hold no data of this satellite.

        Parameters
        ----------
        day : datetime.date
            The UTC day.
        today : datetime.date
            Today, UTC.

        Returns
        -------
        str or None
            Before its launch or after *today*; None within the mission.
        """
        if day < self.launch_day:
            return f"before {self.name}'s launch on {self.launch_day}"
        if day > today:
            return f"after today ({today}, UTC)"
        return None


SNPP_EP, NOAA20_EP = "SNPP_side1_V37_EngPkt.xml", "JPSS1_side1_V115_EngPkt.xml"  # real EPs, monitor/data/ep

# fmt: off
SATELLITES = {s.short: s for s in (
    # short, IDPS, name, bucket, altitude_m, inclination_deg, ltan_h, phase_deg, launch_unix_s,
    #   mission, srf_platform, ep_file, cris_instrument_id, pct_mounting_urad
    Satellite("npp", "NPP", "S-NPP", "noaa-nesdis-snpp-pds", 838.8e3, 98.67, 13.5, 0.0, 1319795281.0,
              "NPP", "npp", SNPP_EP, 1, (-518.45683, -77.760702, 46.109524)),
    Satellite("j01", "J01", "NOAA-20", "noaa-nesdis-n20-pds", 833.0e3, 98.7, 13.5, -90.0, 1510998456.0,
              "S-NPP/JPSS", "n20", NOAA20_EP, 4, (-145.84994, 267.42417, 594.61832)),
    Satellite("j02", "J02", "NOAA-21", "noaa-nesdis-n21-pds", 833.0e3, 98.8, 13.5, 90.0, 1668073765.0,
              "S-NPP/JPSS", "n20", None, None, None),
)}
# fmt: on
PHASE_EPOCH_UNIX_S = 1704067200.0  # 2024-01-01T00:00:00Z
NODAL_PERIOD_S = 101.5 * 60.0  # the shared orbit's period (Lin et al. 2016): the phases keep their spacing


def satellite(short: str) -> Satellite:
    """The satellite of a file-name platform.

    Parameters
    ----------
    short : str
        ``npp``, ``j01`` or ``j02``.

    Returns
    -------
    Satellite
        Its row of the satellite table; a ValueError names the known ones.
    """
    try:
        return SATELLITES[short]
    except KeyError:
        raise DataError(f"unknown satellite {short!r} (known: {', '.join(SATELLITES)})") from None


def _folded(text: str) -> str:
    return text.lower().replace("-", "").replace("_", "").replace(" ", "")


def named(text: str) -> str:
    """The short name of the satellite a user names: ``noaa20``, ``NOAA-20``, ``n20`` and ``j01`` are all
    ``j01``; ``snpp`` and ``npp`` are ``npp``; ``noaa21``, ``n21`` and ``j02`` are ``j02``.

    Parameters
    ----------
    text : str
        A satellite's name, any case, with or without a dash.

    Returns
    -------
    str
        Its short name; a DataError lists the names known.
    """
    key = _folded(text)
    for s in SATELLITES.values():
        if key in s.aliases:
            return s.short
    known = "; ".join(
        f"{s.short} ({', '.join(a for a in s.aliases if a != s.short)})" for s in SATELLITES.values()
    )
    raise DataError(f"{text!r} is not a satellite: {known}")
