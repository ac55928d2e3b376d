"""The embedded store: one SQLite file (:mod:`.database`) with its schema (:mod:`.schema`), the run
ledger (:mod:`.ledger`), the day's results (:mod:`.results`), the outbox of time-series lines
(:mod:`.outbox`) and the alert state, silences and delivery queue (:mod:`.alerts`). All of the service's SQL
lives in this package."""

from __future__ import annotations

from monitor.service.store.database import Database
from monitor.service.store.ledger import RunLedger
from monitor.service.store.outbox import Outbox
from monitor.service.store.results import Results


class Store(Database, RunLedger, Results, Outbox):
    """The SQLite store: its file (:class:`Database`) with its parts side by side, each over that file: the
    ledger, the results and the outbox. One connection per Store; use from one thread at a time."""
