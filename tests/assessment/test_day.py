"""The day's driver's heartbeat: a line every few seconds naming what the day is doing, with the day's log
fields, and none once the day is done."""

import logging
import time

from monitor.assessment.day import Heartbeat
from monitor.core import logcontext


def test_the_heartbeat_names_the_stage_on_time_and_stops_with_the_day(caplog):
    caplog.set_level(logging.INFO, logger="monitor")
    with (
        logcontext.context(satellite="j01", day="2024-06-01"),
        Heartbeat("j01 2024-06-01", every_s=0.05) as b,
    ):
        b.stage("estimate", "estimating the day's offsets")
        time.sleep(0.4)
    beats = [r for r in caplog.records if "into the day" in r.getMessage()]
    assert len(beats) >= 4
    assert beats[-1].getMessage().startswith("j01 2024-06-01: estimating the day's offsets, ")
    n = len(beats)
    time.sleep(0.2)
    assert len([r for r in caplog.records if "into the day" in r.getMessage()]) == n  # stopped with the day
