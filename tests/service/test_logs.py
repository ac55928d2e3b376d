"""Log lines for the journal (priorities, no library chatter) and as JSON (with the satellite-day)."""

import calendar
import io
import json
import logging
import os
import signal
import subprocess
import sys
import time

import pytest

from benchmarks.servers import wait_for
from monitor.core import logcontext
from monitor.service import logs
from tests.invoke import ROOT


@pytest.fixture
def captured(monkeypatch):
    """The root logger set up by :func:`monitor.service.logs.setup` writing into a buffer; restored after."""
    root = logging.getLogger()
    saved = root.handlers[:], root.level
    buffer = io.StringIO()

    def setup(fmt, journal=False):
        # stderr is the journal's stream, and no journald listens: the lines carry their priority
        monkeypatch.setattr(logs, "journal_is_stderr", lambda: journal)
        monkeypatch.setattr(logs, "JOURNAL_SOCKET", "/nonexistent/journal/socket")
        logs.setup(False, fmt)
        root.handlers[0].stream = buffer
        return buffer

    yield setup
    root.handlers[:], _ = saved
    root.setLevel(saved[1])


def test_journal_lines_carry_syslog_priorities_and_libraries_stay_quiet(captured):
    out = captured("text", journal=True)
    log = logging.getLogger("monitor.service")
    log.error("run j01 2024-06-01: failed (SourceError: ...)")
    log.warning("retrying")
    log.info("run j01 2024-06-01: ok")
    logging.getLogger("apscheduler.executors.default").info('Running job "heartbeat"')
    try:
        raise ValueError("boom")
    except ValueError:
        log.exception("unexpected")
    lines = out.getvalue().splitlines()
    assert lines[0] == "<3>ERROR monitor.service: run j01 2024-06-01: failed (SourceError: ...)"
    assert lines[1].startswith("<4>WARNING") and lines[2].startswith("<6>INFO")
    assert not any("heartbeat" in line for line in lines)  # a 30 s job leaves no line at INFO
    assert len(lines) == 4  # a traceback is one journal entry: its lines joined on the event's line
    assert lines[3].startswith("<3>ERROR monitor.service: unexpected | Traceback (most recent call last): | ")
    assert lines[3].endswith(" | ValueError: boom")


def test_text_lines_are_stamped_in_utc_whatever_the_zone(captured, monkeypatch):
    monkeypatch.setenv("TZ", "America/New_York")
    time.tzset()
    try:
        out = captured("text")
        before = time.time()
        logging.getLogger("monitor.service").info("daily at 03:30 UTC")
        stamp = out.getvalue().split(" ", 1)[0]
        assert stamp.endswith("Z")
        logged = calendar.timegm(time.strptime(stamp, "%Y-%m-%dT%H:%M:%SZ"))
        assert abs(logged - before) < 5  # read back as UTC, it is now
    finally:
        monkeypatch.delenv("TZ")
        time.tzset()


def test_json_lines_carry_the_satellite_day_they_belong_to(captured):
    out = captured("json")
    log = logging.getLogger("monitor.pipeline")
    with logcontext.context(satellite="j01", day="2024-06-01", run_id=7):
        logcontext.stage("fetch")
        log.info("fetched")
    log.info("outside")
    inside, outside = (json.loads(line) for line in out.getvalue().splitlines())
    assert inside["satellite"] == "j01" and inside["day"] == "2024-06-01" and inside["run_id"] == "7"
    assert inside["stage"] == "fetch" and inside["priority"] == 6
    assert not {"satellite", "day", "stage", "run_id"} & set(outside)


@pytest.mark.servers
def test_the_daemon_under_systemd_marks_a_failed_run_as_an_error_and_does_not_flood(tmp_path):
    """A daemon whose archive cannot be reached: its failed run is a <3> line (journalctl -p err finds it);
    its heartbeat and scheduler lines are not logged at INFO."""
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
        "source: {kind: nodd, endpoint: 'http://127.0.0.1:9/{bucket}', retries: 0, timeout_s: 2}\n"
        "http: {listen: 'off'}\n"
    )
    err = tmp_path / "stderr"
    with open(err, "w") as fh:  # the journal's stream: JOURNAL_STREAM names this stderr; no journald listens
        st = os.fstat(fh.fileno())
        env = {
            **os.environ,
            "JOURNAL_STREAM": f"{st.st_dev}:{st.st_ino}",
            "CRISGEO_JOURNAL_SOCKET": str(tmp_path / "no-journald"),
            "PYTHONPATH": str(ROOT),
        }
        proc = subprocess.Popen(
            [sys.executable, "-m", "monitor.cli", "daemon", "--config", str(cfg)],
            stderr=fh,
            env=env,
            cwd=ROOT,
        )
    try:  # until the failed run is logged (the catch-up runs at start)
        assert wait_for(lambda: ": failed (" in err.read_text(), 60), err.read_text()
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
    lines = err.read_text().splitlines()
    failed = [line for line in lines if ": failed (" in line]
    assert failed and all(line.startswith("<3>ERROR") for line in failed), lines
    assert all(line.startswith("<") for line in lines if line.strip()), lines
    assert not [line for line in lines if line.startswith("<6>") and "apscheduler" in line], lines


def test_a_day_computed_alone_leaves_no_context_behind(tmp_path, captured):
    """compute_day (as the reprocessing workers call it) names its stages in its own context only."""
    from monitor.archive.local import LocalSource
    from monitor.assessment import compute_day
    from monitor.config.file import load_config

    out = captured("json")
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 's'}\nsource: {{kind: local, path: {tmp_path}}}\n"
    )
    import datetime as dt

    work = compute_day(load_config(cfg), LocalSource(tmp_path), "j01", dt.date(2024, 6, 1))
    assert work.status == "no_data"
    logging.getLogger("monitor.pipeline").info("after")
    assert "stage" not in json.loads(out.getvalue().splitlines()[-1])
