"""The ``schedule`` section: when the daemon runs and which days it (re)assesses (the days themselves:
:mod:`monitor.service.timetable`)."""

from __future__ import annotations

import datetime as dt

from monitor.config.keys import Section, TimeOfDay, key


class ScheduleConfig(Section):
    """The ``schedule`` section: when the daemon runs and which days it (re)assesses."""

    time_utc: TimeOfDay = key(dt.time(3, 30), "Time of the daily run, HH:MM UTC.")
    catch_up_days: int = key(
        7, "Days back (ending lag_days ago) that are assessed when they have no completed run.", 1, 366
    )
    misfire_grace_hours: float = key(
        6.0, "A daily run missed by less than this (e.g. host asleep) still runs.", 0.01, 72
    )
    lag_days: int = key(
        1, "The daily run assesses the day that ended this many days ago (archive latency).", 0, 30
    )
    no_data_retry_days: int = key(
        3,
        "A day found empty is tried again for this many days after it is due, then "
        "recorded as no_data_final.",
        0,
        366,
    )
    run_budget_min: float = key(
        240.0,
        "A satellite-day run longer than this makes /healthz unhealthy and stops "
        "feeding the systemd watchdog (a restart follows). Keep it above "
        "source.run_deadline_min.",
        0.01,
        10080,
    )
