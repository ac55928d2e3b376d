"""``crisgeo status`` as data: per satellite the last run, the latest per-FOR offsets and the alerts
firing; the next run; the outbox; and the Nagios state of it all (0 OK, 1 WARNING, 2 CRITICAL, 3 UNKNOWN).
"""

from __future__ import annotations

from typing import Any

from monitor.config import Config
from monitor.store.alerts import AlertState
from monitor.store.sqlite import Store
from monitor.vocabulary import RunStatus

NAGIOS_OK, NAGIOS_WARNING, NAGIOS_CRITICAL, NAGIOS_UNKNOWN = 0, 1, 2, 3


def status_report(cfg: Config, store: Store, satellites=None) -> dict:
    """What ``crisgeo status`` shows, as data: per satellite (*satellites*, default: the configured ones)
    the last run, the latest per-FOR offsets and the alerts firing; the next run; the outbox size; and the
    Nagios state of it all."""
    runs = {r.satellite: r for r in store.last_runs()}
    chosen = list(satellites or cfg.satellites)
    firing = [a for a in AlertState(store).firing() if a.satellite in chosen or a.satellite is None]
    sats: dict[str, dict[str, Any]] = {}
    for sat in chosen:
        r = runs.get(sat)
        day = store.latest_day(sat)
        sats[sat] = {
            "last_run": None
            if r is None
            else {k: getattr(r, k) for k in ("day", "status", "finished", "reason")},
            "latest_day": None if day is None else str(day),
            "fors": [] if day is None else [f.to_dict() for f in store.day_result(sat, day)],
            "alerts": [
                {k: getattr(a, k) for k in ("rule", "severity", "summary", "started")}
                for a in firing
                if a.satellite == sat
            ],
        }
    critical = any(a.severity == "critical" for a in firing) or any(
        s["last_run"] and s["last_run"]["status"] == RunStatus.FAILED for s in sats.values()
    )
    state = NAGIOS_CRITICAL if critical else NAGIOS_WARNING if firing else NAGIOS_OK
    return {
        "state": ["OK", "WARNING", "CRITICAL"][state],
        "exit": state,
        "satellites": sats,
        "next_run_utc": f"{cfg.schedule.next_run():%Y-%m-%dT%H:%MZ}",
        "outbox": store.outbox_size(),
    }
