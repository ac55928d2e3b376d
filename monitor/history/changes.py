"""Changes that can move the geolocation comparison, and the one that precedes a jump.

Two origins:

* the granule metadata the store keeps per day: the ``*-LUT`` entries of ``N_Aux_Filename`` (for
  example ``VIIRS-SDR-GEO-IMG-PARAM-LUT_*``, ``CMNGEO-PARAM-LUT_*``, ``CrIS-SDR-CC_*``) and the SDR
  software and algorithm versions, compared from one day to the next; ``*-AUX`` entries (engineering
  packet backup, TLE) change every run and are ignored;
* the events calendar (``alerts.events_file``, seeded by ``configs/events.yaml``) and the store's
  ``events`` table (e.g. geolocation-fingerprint changes).
"""

from __future__ import annotations

import datetime as dt
import itertools
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import yaml

from monitor.core.satellites import SATELLITES
from monitor.history.records import History

UTC = dt.timezone.utc
INSTRUMENTS = ("cris", "viirs", "common")
KIND_RE = re.compile(r"^(?P<kind>.+?-LUT)_(?P<plat>npp|j0\d)_")


@dataclass(frozen=True)
class Change:
    """A known change: when, satellite, instrument (cris, viirs, common), kind, description, origin."""

    time: dt.datetime
    satellite: str
    instrument: str  # cris, viirs or common (both: spacecraft-level geolocation LUT)
    kind: str
    description: str
    origin: str  # calendar, metadata, fingerprint

    def label(self) -> str:
        """The change in a few words, for messages and plots.

        Returns
        -------
        str
            The label.
        """
        who = {"cris": "CrIS", "viirs": "VIIRS", "common": "CrIS and VIIRS (common geolocation)"}[
            self.instrument
        ]
        return f"{who} {self.kind} on {self.time:%Y-%m-%d %H:%M} UTC: {self.description} [{self.origin}]"


def _when(value: object) -> dt.datetime:
    if isinstance(value, dt.datetime):
        return value if value.tzinfo else value.replace(tzinfo=UTC)
    if isinstance(value, dt.date):
        return dt.datetime(value.year, value.month, value.day, tzinfo=UTC)
    return dt.datetime.fromisoformat(str(value).replace("Z", "+00:00")).astimezone(UTC)


def load_calendar(path: str | Path) -> list[Change]:
    """Events of the calendar YAML at *path* (missing file: none). Errors name the entry and key.

    Parameters
    ----------
    path : str or Path
        The calendar YAML.

    Returns
    -------
    list of Change
        Its events; none for a missing file.
    """
    path = Path(path)
    if not path.exists():
        return []
    doc = yaml.safe_load(path.read_text()) or {}
    out = []
    for i, e in enumerate(doc.get("events") or []):
        where = f"{path}: events[{i}]"
        try:
            inst = e["instrument"]
            if inst not in INSTRUMENTS:
                raise ValueError(f"instrument {inst!r} is not one of {', '.join(INSTRUMENTS)}")
            out.append(
                Change(
                    _when(e["time"]),
                    e["satellite"],
                    inst,
                    e.get("kind", "change"),
                    str(e.get("description", "")).strip(),
                    "calendar",
                )
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{where}: {exc}") from None
    return out


def add_to_calendar(path: str | Path, change: Change) -> None:
    """Append *change* to the calendar YAML at *path* (created if missing). The file is edited as a
    round trip (ruamel.yaml): its comments, order and quoting stay as the team wrote them. A change the
    calendar already holds (same satellite, time, instrument and kind) is a ValueError naming it.

    Parameters
    ----------
    path : str or Path
        The calendar YAML.
    change : Change
        The change.
    """
    from ruamel.yaml import YAML

    path = Path(path)
    same = (change.satellite, change.time, change.instrument, change.kind)
    for old in load_calendar(path):
        if (old.satellite, old.time, old.instrument, old.kind) == same:
            raise ValueError(f"{path}: already in the calendar: {old.label()}")
    rt = YAML()  # round-trip mode
    rt.preserve_quotes = True
    rt.width = 4096  # long descriptions stay on their lines
    rt.indent(mapping=2, sequence=4, offset=2)
    doc = (rt.load(path.read_text()) if path.exists() else None) or {}
    if not isinstance(doc, dict) or not isinstance(doc.get("events", []) or [], list):
        raise ValueError(f"{path}: expected a mapping with an events list")
    if doc.get("events") is None:
        doc["events"] = []
    doc["events"].append(
        {
            "satellite": change.satellite,
            "time": change.time.strftime("%Y-%m-%dT%H:%M:%SZ"),
            "instrument": change.instrument,
            "kind": change.kind,
            "description": change.description,
        }
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".part")
    with open(tmp, "w") as fh:
        rt.dump(doc, fh)
    tmp.replace(path)


def _lut_kinds(names: Iterable[str]) -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for n in names:
        m = KIND_RE.match(n)
        if m:
            out.setdefault(m["kind"], set()).add(n)
    return out


def metadata_changes(store: History, satellite: str, since: dt.date | None = None) -> list[Change]:
    """Changes of LUTs and SDR software between consecutive days of stored granule metadata (the days
    from *since* on: the changes after its first day).

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    since : datetime.date, optional
        The first day read; None: every day.

    Returns
    -------
    list of Change
        In time order.
    """
    days: dict[str, dict[str, set[str]]] = {}
    for g in store.granules(satellite, since=since):
        d = days.setdefault(g.day, {"cris": set(), "viirs": set(), "cris_sw": set(), "viirs_sw": set()})
        d["cris"].update(g.cris_aux)
        d["viirs"].update(g.viirs_aux)
        if g.software_version:
            d["cris_sw"].add(f"{g.software_version} / algorithm {g.algorithm_version}")
        if g.viirs_software:
            d["viirs_sw"].add(g.viirs_software)
    out = []
    ordered = sorted(days)
    for prev, cur in itertools.pairwise(ordered):
        a, b = days[prev], days[cur]
        when = _when(cur)
        for inst in ("cris", "viirs"):
            ka, kb = _lut_kinds(a[inst]), _lut_kinds(b[inst])
            for kind in sorted(set(ka) | set(kb)):
                if ka.get(kind) != kb.get(kind):
                    instrument = "common" if kind.startswith("CMNGEO") else inst
                    new = ", ".join(sorted(kb.get(kind, {"(none)"})))
                    out.append(
                        Change(when, satellite, instrument, "lut_change", f"{kind} now {new}", "metadata")
                    )
            if a[f"{inst}_sw"] and b[f"{inst}_sw"] and a[f"{inst}_sw"] != b[f"{inst}_sw"]:
                out.append(
                    Change(
                        when,
                        satellite,
                        inst,
                        "software",
                        f"SDR software {', '.join(sorted(a[inst + '_sw']))} -> "
                        f"{', '.join(sorted(b[inst + '_sw']))}",
                        "metadata",
                    )
                )
    unique: dict[tuple, Change] = {}
    for c in out:  # a common LUT appears in both instruments' lists
        unique.setdefault((c.time, c.instrument, c.description), c)
    return list(unique.values())


def stored_changes(store: History, satellite: str) -> list[Change]:
    """Change events the service itself recorded (``events`` rows of kind ``change:<instrument>``).

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.

    Returns
    -------
    list of Change
        In time order.
    """
    out = []
    for e in store.events():
        if e.kind.is_change and e.satellite == satellite and "time" in e.detail:
            d = e.detail
            out.append(
                Change(
                    _when(d["time"]),
                    satellite,
                    e.kind.value.split(":", 1)[1],
                    d.get("kind", "change"),
                    d.get("description", ""),
                    d.get("origin", "service"),
                )
            )
    return out


def all_changes(
    store: History, satellite: str, calendar_path: str | Path | None = None, since: dt.date | None = None
) -> list[Change]:
    """Every known change of *satellite*, in time order: the calendar, the metadata, the recorded events
    (when *since* is given, those after that day: the metadata is read from that day on).

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    calendar_path : str or Path, optional
        The events calendar.
    since : datetime.date, optional
        Only the changes after this day; None: all.

    Returns
    -------
    list of Change
        In time order.
    """
    cal = [c for c in load_calendar(calendar_path) if c.satellite == satellite] if calendar_path else []
    found = cal + metadata_changes(store, satellite, since) + stored_changes(store, satellite)
    if since is not None:
        found = [c for c in found if c.time.date() > since]
    return sorted(found, key=lambda c: c.time)


def listing(
    calendar_path: str | Path, configured: Iterable[str], only: str | None, store: History | None
) -> list[Change]:
    """What ``crisgeo events list`` shows: the changes of satellite *only*, else of every satellite the
    calendar or the configuration (*configured*) names, in the satellite table's order, each in time
    order. Before the first run (*store* None) the calendar alone; after, the metadata and recorded events
    too.

    Parameters
    ----------
    calendar_path : str or Path
        The events calendar.
    configured : iterable of str
        The configured satellites.
    only : str or None
        One satellite.
    store : History or None
        The store's records, for the changes found in the data.

    Returns
    -------
    list of Change
        In time order.
    """
    calendar = load_calendar(calendar_path)
    known = {c.satellite for c in calendar} | set(configured)
    chosen = [only] if only else [s for s in SATELLITES if s in known]
    if store is None:
        return [c for c in sorted(calendar, key=lambda c: c.time) if c.satellite in chosen]
    return [c for sat in chosen for c in all_changes(store, sat, calendar_path)]


def preceding_change(changes: list[Change], split_day: dt.date, window_days: int = 10) -> Change | None:
    """The latest change at or before the end of *split_day* and no more than *window_days* before it.

    Parameters
    ----------
    changes : list of Change
        Known changes, in time order.
    split_day : datetime.date
        The day a step was found at.
    window_days : int, optional
        How far back a change may lie, days.

    Returns
    -------
    Change or None
        The change; None without one.
    """
    end = _when(split_day) + dt.timedelta(days=1)
    start = end - dt.timedelta(days=window_days + 1)
    before = [c for c in changes if start <= c.time < end]
    return max(before, key=lambda c: c.time) if before else None
