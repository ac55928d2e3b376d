"""The days the schedule (``schedule`` section) asks for: the catch-up window, the day after which an empty
day is not tried again, the next daily run."""

from __future__ import annotations

import datetime as dt

from monitor.config.schedule import ScheduleConfig


def no_data_horizon(schedule: ScheduleConfig, today: dt.date) -> dt.date:
    """Days before this one that were found empty are not tried again (their no_data is final).

    Parameters
    ----------
    schedule : ScheduleConfig
        The ``schedule`` section.
    today : datetime.date
        Today, UTC.

    Returns
    -------
    datetime.date
        Days before it that were found empty are not tried again.
    """
    return today - dt.timedelta(days=schedule.lag_days + schedule.no_data_retry_days)


def catch_up(schedule: ScheduleConfig, done: set[dt.date], today: dt.date) -> list[dt.date]:
    """The days of the catch-up window (ending lag_days before *today*) not in *done*, oldest first.

    Parameters
    ----------
    schedule : ScheduleConfig
        The ``schedule`` section.
    done : set of datetime.date
        The days done.
    today : datetime.date
        Today, UTC.

    Returns
    -------
    list of datetime.date
        The missed days, oldest first.
    """
    last = today - dt.timedelta(days=schedule.lag_days)
    return sorted(
        d for d in (last - dt.timedelta(days=k) for k in range(schedule.catch_up_days)) if d not in done
    )


def next_run(schedule: ScheduleConfig, now: dt.datetime | None = None) -> dt.datetime:
    """The next scheduled daily run (UTC) after *now*.

    Parameters
    ----------
    schedule : ScheduleConfig
        The ``schedule`` section.
    now : datetime.datetime, optional
        Now, UTC.

    Returns
    -------
    datetime.datetime
        The next run, UTC.
    """
    now = now or dt.datetime.now(dt.timezone.utc)
    t = schedule.time_utc
    nxt = now.replace(hour=t.hour, minute=t.minute, second=0, microsecond=0)
    return nxt if nxt > now else nxt + dt.timedelta(days=1)
