"""The day's driver's heartbeat: a line every few seconds naming what the day is doing, with the day's log
fields, and none once the day is done."""

import logging
import threading

from monitor.assessment.day import Heartbeat
from monitor.core import logcontext


class _Beats(logging.Handler):
    """Counts the heartbeat's lines and says when *enough* have come."""

    def __init__(self, enough: int) -> None:
        super().__init__(logging.INFO)
        self.lines: list[str] = []
        self.enough, self.came = enough, threading.Event()

    def emit(self, record: logging.LogRecord) -> None:
        if "into the day" in record.getMessage():
            self.lines.append(record.getMessage())
            if len(self.lines) >= self.enough:
                self.came.set()


def test_the_heartbeat_names_the_stage_on_time_and_stops_with_the_day():
    beats = _Beats(4)
    logger = logging.getLogger("monitor")
    logger.addHandler(beats)
    level, logger.level = logger.level, logging.INFO
    try:
        with (
            logcontext.context(satellite="j01", day="2024-06-01"),
            Heartbeat("j01 2024-06-01", every_s=0.05) as b,
        ):
            b.stage("estimate", "estimating the day's offsets")
            assert beats.came.wait(10)  # four beats, one every 0.05 s
        assert beats.lines[-1].startswith("j01 2024-06-01: estimating the day's offsets, ")
        assert not b._thread.is_alive()  # stopped with the day: no beat can follow
    finally:
        logger.removeHandler(beats)
        logger.setLevel(level)
