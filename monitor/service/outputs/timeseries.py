"""Publishing per-FOR results to a time-series database, through the SQLite outbox.

Measurement ``cris_geolocation`` (configurable), one point per satellite, day and FOR, time = the day at
00:00 UTC, precision seconds.

* tags: ``satellite`` (npp, j01, j02) and ``for`` (01..30)
* fields: every measured field of the FOR whose declaration publishes it (``series``,
  :func:`monitor.core.result.measures`), named as declared (a float, or an integer: n_samples); boolean
  field: reliable

The fields measured per VIIRS band go to ``cris_geolocation_band``, one point per satellite, day, FOR and
band: tags ``satellite``, ``for`` and ``band`` (I5, M13, M15, M16), fields named without the band
(``cris_minus_viirs_k``, ``sigma_cris_minus_viirs_k``).

Known changes (calendar, metadata, fingerprint) go to ``cris_geolocation_change`` (see :func:`change_lines`),
re-sent after every run, for the dashboards' annotations.

A field's type never changes (InfluxDB 1.x rejects a type change), and a non-finite value is left out of
its point rather than written (InfluxDB rejects NaN; VictoriaMetrics would store garbage). Points are
queued in the store's outbox in the same transaction as the day's results and deleted only once the
server has accepted them: a server that is down gets them at the next drain, none is lost or sent twice.

Two writers: ``influx2`` uses influxdb-client's v2 write API (InfluxDB 2.x/3.x, 1.8+, VictoriaMetrics);
``influx1`` posts line protocol to ``/write`` (InfluxDB 1.x before 1.8, where /api/v2/write is missing).
"""

from __future__ import annotations

import datetime as dt
import logging
import math
from collections.abc import Iterable
from typing import NamedTuple

import requests
from influxdb_client import InfluxDBClient, Point, WritePrecision
from influxdb_client.client.exceptions import InfluxDBError
from influxdb_client.client.write_api import SYNCHRONOUS

from monitor.config.outputs import PublishConfig
from monitor.core.result import AssessmentResult, ForOffset, measures
from monitor.history.changes import Change
from monitor.service.store.outbox import QueuedLines
from monitor.service.store.sqlite import Store

LOG = logging.getLogger(__name__)


BAND_SUFFIX = "_band"  # the measurement of the fields measured per VIIRS band: cris_geolocation_band


class PublishError(RuntimeError):
    """The time-series server did not accept a batch; the points stay in the outbox."""


def result_lines(measurement: str, satellite: str, day: dt.date, fors: Iterable[ForOffset]) -> list[str]:
    """Line-protocol points of one day's per-FOR results.

    Parameters
    ----------
    measurement : str
        The measurement (``cris_geolocation``).
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day (the points' time).
    fors : iterable of ForOffset
        The day's FORs.

    Returns
    -------
    list of str
        Line-protocol points: one per FOR, and one per FOR and band measured.
    """
    when = dt.datetime(day.year, day.month, day.day, tzinfo=dt.timezone.utc)
    lines = []
    for f in fors:
        p = Point(measurement).tag("satellite", satellite).tag("for", f"{f.for_index:02d}")
        per_band: dict[str, Point] = {}
        for m in measures(type(f)):
            value = getattr(f, m.name)
            if not (m.series and value is not None and math.isfinite(value)):
                continue
            if m.band is None:
                p = p.field(m.name, m.kind(value))
            else:
                if m.band not in per_band:
                    per_band[m.band] = (
                        Point(f"{measurement}{BAND_SUFFIX}")
                        .tag("satellite", satellite)
                        .tag("for", f"{f.for_index:02d}")
                        .tag("band", m.band)
                    )
                per_band[m.band] = per_band[m.band].field(m.quantity, m.kind(value))
        p = p.field("reliable", bool(f.reliable))
        lines.append(p.time(when, WritePrecision.S).to_line_protocol())
        lines += [b.time(when, WritePrecision.S).to_line_protocol() for b in per_band.values()]
    return lines


def day_lines(
    publish: Iterable[PublishConfig], satellite: str, day: dt.date, result: AssessmentResult
) -> list[QueuedLines]:
    """The lines of a day's *result* for each configured time-series store, queued with the day's results
    (:meth:`monitor.service.store.sqlite.Store.save_day`).

    Parameters
    ----------
    publish : iterable of PublishConfig
        The configured time-series stores.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    result : AssessmentResult
        The day's result.

    Returns
    -------
    list of QueuedLines
        Per target, its lines.
    """
    return [
        QueuedLines(target_name(p), result_lines(p.measurement, satellite, day, result.fors)) for p in publish
    ]


def change_lines(measurement: str, changes: Iterable[Change]) -> list[str]:
    """Line-protocol points of known changes (measurement ``<measurement>_change``, for dashboard
    annotations).

    Tags satellite, instrument, kind, origin; string field ``description``; time = the change time. The
    same change written again overwrites its point (same measurement, tags and time).

    Parameters
    ----------
    measurement : str
        The results' measurement.
    changes : iterable of Change
        Known changes.

    Returns
    -------
    list of str
        Line-protocol points.
    """
    lines = []
    for c in changes:
        p = (
            Point(f"{measurement}_change")
            .tag("satellite", c.satellite)
            .tag("instrument", c.instrument)
            .tag("kind", c.kind)
            .tag("origin", c.origin)
            .field("description", c.description)
        )
        lines.append(p.time(c.time, WritePrecision.S).to_line_protocol())
    return lines


def target_name(cfg: PublishConfig) -> str:
    """Outbox target of a publisher (kind and URL; never a credential).

    Parameters
    ----------
    cfg : PublishConfig
        A publisher.

    Returns
    -------
    str
        Its kind and URL.
    """
    return f"{cfg.kind}:{cfg.url}"


class Influx2Writer:
    """v2 write API through influxdb-client, synchronous so that every failure is seen.

    Parameters
    ----------
    cfg : PublishConfig
        The publisher (``kind: influx2``).
    """

    def __init__(self, cfg: PublishConfig):
        self.cfg = cfg
        self.client = InfluxDBClient(
            url=cfg.url, token=cfg.secret("token_env") or "", org=cfg.org, timeout=int(cfg.timeout_s * 1000)
        )
        self.api = self.client.write_api(write_options=SYNCHRONOUS)

    def write(self, lines: list[str]) -> None:
        """Write line-protocol *lines*; raises on any failure (the outbox keeps them).

        Parameters
        ----------
        lines : list of str
            Line-protocol points.
        """
        try:
            self.api.write(
                bucket=self.cfg.bucket,
                org=self.cfg.org,
                record=lines,
                write_precision=WritePrecision.S,  # type: ignore[arg-type]
            )
        except InfluxDBError as exc:
            raise PublishError(
                f"{self.cfg.url}: HTTP {getattr(exc, 'status', '?')} {getattr(exc, 'message', exc)}"
            ) from None
        except Exception as exc:  # urllib3 raises its own errors when the server is unreachable
            raise PublishError(f"{self.cfg.url}: {type(exc).__name__}: {exc}") from None

    def close(self) -> None:
        """Close the client."""
        self.client.close()


class Influx1Writer:
    """InfluxDB 1.x ``/write`` with line protocol; creates the database once if it is missing.

    Parameters
    ----------
    cfg : PublishConfig
        The publisher (``kind: influx1``).
    """

    def __init__(self, cfg: PublishConfig):
        self.cfg = cfg
        user, password = cfg.secret("username_env"), cfg.secret("password_env")
        self.auth = (user, password or "") if user else None

    def _post(self, lines: list[str]) -> requests.Response:
        return requests.post(
            f"{self.cfg.url}/write",
            params={"db": self.cfg.database, "precision": "s"},
            data="\n".join(lines).encode(),
            auth=self.auth,
            timeout=self.cfg.timeout_s,
        )

    def write(self, lines: list[str]) -> None:
        """POST line-protocol *lines* to /write; raises on any failure (the outbox keeps them).

        Parameters
        ----------
        lines : list of str
            Line-protocol points.
        """
        try:
            r = self._post(lines)
            if r.status_code == 404 and "database not found" in r.text:
                requests.post(
                    f"{self.cfg.url}/query",
                    data={"q": f'CREATE DATABASE "{self.cfg.database}"'},
                    auth=self.auth,
                    timeout=self.cfg.timeout_s,
                ).raise_for_status()
                r = self._post(lines)
        except requests.RequestException as exc:
            raise PublishError(f"{self.cfg.url}: {type(exc).__name__}") from None
        if r.status_code != 204:
            raise PublishError(f"{self.cfg.url}: HTTP {r.status_code} {r.text[:200]}")

    def close(self) -> None:
        """Close the session."""
        pass


WRITERS: dict[str, type[Influx2Writer] | type[Influx1Writer]] = {
    "influx2": Influx2Writer,
    "influx1": Influx1Writer,
}


class Drained(NamedTuple):
    """What one drain of the outbox did for a target: points sent, points left waiting."""

    sent: int
    left: int


def drain_outbox(store: Store, publish_cfgs: list[PublishConfig], batch: int = 5000) -> dict[str, Drained]:
    """Send every queued point to its server; returns {target: (sent, left)}. Never raises for a server.

    Parameters
    ----------
    store : Store
        The store.
    publish_cfgs : list of PublishConfig
        The publishers.
    batch : int, optional
        Points per request.

    Returns
    -------
    dict of str to Drained
        Per target, the points sent and left.
    """
    report = {}
    for cfg in publish_cfgs:
        target = target_name(cfg)
        writer: Influx2Writer | Influx1Writer = WRITERS[cfg.kind](cfg)
        sent = 0
        try:
            while True:
                rows = store.outbox(target, batch)
                if not rows:
                    break
                try:
                    writer.write([r["line"] for r in rows])
                except PublishError as exc:
                    store.outbox_failed([r["id"] for r in rows], str(exc))
                    LOG.warning(
                        "publishing to %s failed, %d points wait in the outbox: %s",
                        target,
                        store.outbox_size(target),
                        exc,
                    )
                    break
                store.outbox_delivered([r["id"] for r in rows])
                sent += len(rows)
        finally:
            writer.close()
        report[target] = Drained(sent, store.outbox_size(target))
    return report
