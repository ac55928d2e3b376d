"""The journal: entries with fields on journald's native socket, read back with journalctl; the journal's
stream recognised by stderr's device and inode. A real systemd-journald runs here, started by the test
when the machine has none running (a container without systemd as PID 1)."""

from __future__ import annotations

import json
import logging
import os
import shutil
import socket
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from monitor.core import logcontext
from monitor.service import logs

JOURNALD = next(
    (p for p in ("/lib/systemd/systemd-journald", "/usr/lib/systemd/systemd-journald") if Path(p).exists()),
    None,
)


def _listening() -> bool:
    """Whether a journald listens on the native socket (a socket file may outlive its journald)."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as s:
        try:
            s.connect(logs.JOURNAL_SOCKET)
            return True
        except OSError:
            return False


@pytest.fixture(scope="module")
def journald():
    if JOURNALD is None or shutil.which("journalctl") is None or os.geteuid() != 0:
        pytest.skip("systemd-journald and journalctl (the Debian package systemd), as root, are needed")
    started = None
    if not _listening():
        started = subprocess.Popen([JOURNALD], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for _ in range(200):
            if _listening():
                break
            time.sleep(0.05)
    yield
    if started is not None:
        started.terminate()
        started.wait(10)


def _entries(**match) -> list[dict]:
    """The journal's entries matching FIELD=value, read with journalctl (synced first)."""
    subprocess.run(["journalctl", "--sync"], capture_output=True, timeout=30)
    words = [f"{k}={v}" for k, v in match.items()]
    out = subprocess.run(
        ["journalctl", "-o", "json", "--no-pager", *words], capture_output=True, text=True, timeout=30
    )
    return [json.loads(line) for line in out.stdout.splitlines() if line.strip()]


def _wait_for(**match) -> list[dict]:
    for _ in range(100):
        found = _entries(**match)
        if found:
            return found
        time.sleep(0.1)
    return []


def test_a_line_is_an_entry_with_its_satellite_day_and_alert(journald):
    tag = uuid.uuid4().hex
    log = logging.getLogger(f"monitor.test.{tag}")
    log.propagate = False
    log.setLevel(logging.DEBUG)
    handler = logs.JournalHandler()
    log.addHandler(handler)
    try:
        with logcontext.context(satellite="j01", day="2026-12-01", run_id=7):
            log.warning("a day's line %s", tag)
            log.info("FIRING spec:j01 (critical): %s", tag, extra={"alert": "spec:j01"})
        try:
            raise ValueError("a traceback\nover lines")
        except ValueError:
            log.exception("failed %s", tag)
    finally:
        log.removeHandler(handler)
        handler.close()
    failed = _wait_for(PRIORITY="3", LOGGER=f"monitor.test.{tag}")  # the last sent: the others are in
    assert len(failed) == 1 and "ValueError: a traceback" in failed[0]["MESSAGE"]
    day = _entries(SATELLITE="j01", DAY="2026-12-01", LOGGER=f"monitor.test.{tag}")
    assert len(day) >= 2, day
    first = next(e for e in day if tag in e["MESSAGE"] and "a day's line" in e["MESSAGE"])
    assert first["PRIORITY"] == "4" and first["SYSLOG_IDENTIFIER"] == "crisgeo" and first["RUN_ID"] == "7"
    alert = _entries(ALERT="spec:j01", LOGGER=f"monitor.test.{tag}")
    assert len(alert) == 1 and alert[0]["PRIORITY"] == "6" and alert[0]["SATELLITE"] == "j01"


def test_the_journals_stream_is_known_by_stderrs_device_and_inode(tmp_path):
    """systemd.exec(5): JOURNAL_STREAM names the stream's device and inode; a child whose stderr is
    another file (a pipe, a file) while it inherited the variable is not writing to the journal."""
    err = tmp_path / "stderr"
    with open(err, "w") as fh:
        st = os.fstat(fh.fileno())
        code = "from monitor.service.logs import journal_is_stderr; print(journal_is_stderr())"
        for stream, expected in (
            (f"{st.st_dev}:{st.st_ino}", "True"),
            (f"{st.st_dev}:{st.st_ino + 1}", "False"),
            ("", "False"),
        ):
            env = {**os.environ, "JOURNAL_STREAM": stream}
            out = subprocess.run(
                [sys.executable, "-c", code],
                stderr=fh,
                capture_output=False,
                stdout=subprocess.PIPE,
                text=True,
                env=env,
                timeout=60,
            )
            assert out.stdout.strip() == expected, stream


def test_a_value_over_lines_is_sent_with_its_length():
    entry = logs.encode_entry({"MESSAGE": "one\ntwo", "PRIORITY": "6"})
    assert entry == b"MESSAGE\n" + (7).to_bytes(8, "little") + b"one\ntwo\nPRIORITY=6\n"
