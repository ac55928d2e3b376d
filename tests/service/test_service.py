"""The service as a process: SIGKILL mid-run, SIGTERM mid-run, the daemon under a fake systemd, the unit."""

import datetime as dt
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from benchmarks.servers import wait_for
from monitor.history.records import Message
from monitor.service.store.sqlite import Store
from tests.invoke import CRISGEO, ROOT, run_crisgeo

DAY = "2024-06-01"


def _config(tmp_path, data, workers=1, slow=False):
    """A configuration; *slow* makes the assessment ~4x the work (41 x 41 cones of the four discs), so that
    a signal lands mid-run."""
    heavy = ", half_steps: 20" if slow else ""
    p = tmp_path / "c.yaml"
    p.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {data}}}\n"
        f"assessment: {{workers: {workers}{heavy}}}\nschedule: {{catch_up_days: 2}}\n"
    )
    return p


def _status(db):
    if not db.exists():
        return []
    s = Store(db)
    try:
        return [r.status for r in s.runs()]
    finally:
        s.close()


def _assessing(proc_log: Path):
    """The run's log says the assessment (selection done, granules fetched) has begun."""
    return proc_log.exists() and "assessing " in proc_log.read_text()


@pytest.mark.servers
def test_sigkill_mid_run_then_restart_redoes_the_day(cases, tmp_path):
    data, _, _ = cases.get()
    cfg = _config(tmp_path, data, slow=True)
    db = tmp_path / "state" / "crisgeo.sqlite"
    log = tmp_path / "log"
    with open(log, "w") as fh:
        p = subprocess.Popen(
            CRISGEO + ["run", "--config", str(cfg), "--date", DAY], stdout=fh, stderr=fh, cwd=ROOT
        )
    assert wait_for(lambda: _assessing(log))  # inside the assessment: nothing is stored before it ends
    p.kill()
    p.wait()
    s = Store(db)
    assert [r.status for r in s.runs()] == ["running"]
    assert s.day_result("j01", dt.date.fromisoformat(DAY)) == []  # nothing half-written
    s.close()
    cfg = _config(tmp_path, data)
    r = run_crisgeo("run", "--config", cfg, "--date", DAY)
    assert r.returncode == 0, r.stderr
    s = Store(db)
    assert [r.status for r in s.runs()] == ["interrupted", "ok"]
    assert len(s.day_result("j01", dt.date.fromisoformat(DAY))) == 30


@pytest.mark.servers
@pytest.mark.parametrize("workers,sig", [(1, signal.SIGTERM), (2, signal.SIGINT)])
def test_a_signal_mid_run_stops_within_seconds_with_its_exit_status(cases, tmp_path, workers, sig):
    """SIGTERM (systemd) or SIGINT (Ctrl-C) mid-assessment: the run is recorded interrupted, nothing is
    half-written, and the exit status is the shell's 128 + the signal (143, 130), within seconds."""
    data, _, _ = cases.get()
    cfg = _config(tmp_path, data, workers, slow=True)
    log = tmp_path / "log"
    with open(log, "w") as fh:
        p = subprocess.Popen(
            CRISGEO + ["run", "--config", str(cfg), "--date", DAY], stdout=fh, stderr=fh, cwd=ROOT
        )
    assert wait_for(lambda: _assessing(log))  # the stop must come from within the compiled kernels' loop
    t0 = time.time()
    p.send_signal(sig)
    p.wait(timeout=60)
    stopped_in = time.time() - t0
    assert stopped_in < 20, stopped_in  # "within seconds": a granule's collocation at most, on a busy machine
    assert p.returncode == 128 + sig, log.read_text()[-2000:]
    assert _status(tmp_path / "state" / "crisgeo.sqlite") == ["interrupted"]
    s = Store(tmp_path / "state" / "crisgeo.sqlite")
    assert s.day_result("j01", dt.date.fromisoformat(DAY)) == []


@pytest.mark.servers
def test_sigint_while_simulating_stops_within_a_step_and_leaves_no_half_day(tmp_path):
    """The offline default simulates the day first (tens of seconds): a Ctrl-C then ends the run within a
    granule's step, exit status 130, the day recorded interrupted and no half-simulated day left behind
    (the next run simulates it whole)."""
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
        "source: {kind: simulated, granules: 3}\nschedule: {catch_up_days: 1}\n"
    )
    log = tmp_path / "log"
    with open(log, "w") as fh:
        p = subprocess.Popen(
            CRISGEO + ["run", "--config", str(cfg), "--date", DAY], stdout=fh, stderr=fh, cwd=ROOT
        )
    assert wait_for(lambda: "simulating 3 CrIS granules" in log.read_text(), 60), log.read_text()
    # into the simulation: its first granule written
    assert wait_for(lambda: any((tmp_path / "state").rglob("*.h5")), 60), log.read_text()
    t0 = time.time()
    p.send_signal(signal.SIGINT)
    p.wait(timeout=60)
    assert time.time() - t0 < 15, log.read_text()[-2000:]
    assert p.returncode == 130, log.read_text()[-2000:]
    assert _status(tmp_path / "state" / "crisgeo.sqlite") == ["interrupted"]
    assert not list((tmp_path / "state").rglob("truth.json"))
    assert not [d for d in (tmp_path / "state").rglob(DAY) if d.is_dir()]


@pytest.mark.servers
def test_daemon_notifies_systemd_and_stops_on_sigterm(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    cfg = _config(tmp_path, empty)
    sock_path = str(tmp_path / "notify.sock")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(sock_path)
    sock.settimeout(0.5)
    got: set[str] = set()
    done = threading.Event()

    def read():  # read the notify socket as systemd does, all along: its queue holds 10 messages only
        while not done.is_set():
            try:
                got.add(sock.recv(4096).decode())
            except TimeoutError:
                continue

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    env = dict(os.environ, NOTIFY_SOCKET=sock_path, WATCHDOG_USEC="400000")
    with open(tmp_path / "daemon.log", "w") as log:
        p = subprocess.Popen(
            CRISGEO + ["daemon", "--config", str(cfg), "--listen", "127.0.0.1:0"],  # no fixed port to collide
            env=env,
            cwd=ROOT,
            stdout=log,
            stderr=log,
        )
    try:
        assert wait_for(lambda: {"READY=1", "WATCHDOG=1"} <= got, 60), got
        # the catch-up runs at start and records the days without data
        assert wait_for(lambda: _status(tmp_path / "state" / "crisgeo.sqlite").count("no_data") == 2, 60)
        # a second instance on the same state directory is refused
        r = run_crisgeo("run", "--config", cfg)
        assert (
            r.returncode == 75 and "another crisgeo process (pid" in r.stderr and "systemctl stop" in r.stderr
        )
        p.send_signal(signal.SIGTERM)
        # the shell's 128 + 15, which the shipped unit counts as success: systemctl stop leaves it inactive,
        # not failed, and Restart=on-failure does not start it again (no systemd runs as PID 1 here to stop
        # it for real: the exit status and the unit's SuccessExitStatus are checked side by side)
        code = p.wait(timeout=20)
        unit = (ROOT / "systemd" / "crisgeo.service").read_text()
        success = re.search(r"^SuccessExitStatus=(.+)$", unit, re.MULTILINE)
        assert code == 128 + signal.SIGTERM and success and str(code) in success.group(1).split()
        assert wait_for(lambda: "STOPPING=1" in got, 10), got
    finally:
        done.set()
        if p.poll() is None:
            p.kill()
        reader.join(timeout=5)
        sock.close()


@pytest.mark.servers
def test_daemon_stops_even_when_nobody_reads_its_notify_socket(tmp_path):
    """A notify socket whose queue is full (a wedged systemd) must not block the daemon: its keep-alives
    are dropped, and SIGTERM still stops it at once (it used to hang in the handler's STOPPING=1)."""
    empty = tmp_path / "empty"
    empty.mkdir()
    cfg = _config(tmp_path, empty)
    sock_path = str(tmp_path / "notify.sock")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(sock_path)  # bound, never read
    env = dict(os.environ, NOTIFY_SOCKET=sock_path, WATCHDOG_USEC="2000")  # a keep-alive every ms
    log = tmp_path / "daemon.log"
    with open(log, "w") as fh:
        p = subprocess.Popen(
            CRISGEO + ["-v", "daemon", "--config", str(cfg), "--listen", "off"],
            env=env,
            cwd=ROOT,
            stdout=fh,
            stderr=fh,
        )
    try:
        assert wait_for(lambda: _status(tmp_path / "state" / "crisgeo.sqlite").count("no_data") == 2, 60)
        # the queue is full: the daemon's debug log says a keep-alive was dropped
        assert wait_for(lambda: "sd_notify WATCHDOG not delivered" in log.read_text(), 60), log.read_text()[
            -2000:
        ]
        p.send_signal(signal.SIGTERM)
        assert p.wait(timeout=30) == 128 + signal.SIGTERM  # a clean stop (the unit's SuccessExitStatus)
    finally:
        if p.poll() is None:
            p.kill()
        sock.close()


def test_status_command(cases, tmp_path):
    data, _, _ = cases.get()
    cfg = _config(tmp_path, tmp_path / "none")
    (tmp_path / "none").mkdir()
    r = run_crisgeo("status", "--config", cfg)  # before the daemon's first start: no store, none made
    assert r.returncode == 3 and r.stdout.startswith("UNKNOWN - ") and "no crisgeo store here yet" in r.stdout
    assert not (tmp_path / "state" / "crisgeo.sqlite").exists()
    Store(tmp_path / "state" / "crisgeo.sqlite").close()  # as the daemon does when it starts
    r = run_crisgeo("status", "--config", cfg)
    assert r.returncode == 0 and "j01: no run yet" in r.stdout and "outbox: 0" in r.stdout


def _verify(unit: Path):
    return subprocess.run(["systemd-analyze", "verify", str(unit)], capture_output=True, text=True)


@pytest.mark.servers
@pytest.mark.skipif(shutil.which("systemd-analyze") is None, reason="systemd-analyze not installed")
def test_systemd_unit_verifies_without_any_warning(tmp_path):
    text = (ROOT / "systemd" / "crisgeo.service").read_text()
    assert "Type=notify" in text and "WatchdogSec=" in text and "ProtectSystem=strict" in text
    # ExecStart must name an existing program on the test machine
    unit = tmp_path / "crisgeo.service"
    unit.write_text(text.replace("/opt/crisgeo/.venv/bin/crisgeo", sys.executable + " -m monitor.cli"))
    r = _verify(unit)
    assert r.returncode == 0 and r.stderr.strip() == "", r.stderr
    bad = tmp_path / "crisgeo-bad.service"
    bad.write_text(unit.read_text().replace("Restart=on-failure", "Restrat=on-failure"))
    assert "Unknown key" in _verify(bad).stderr  # the check above can fail
    # the reload, the memory limit and the credentials the comments show are the unit's own keys
    assert "ExecReload=/bin/kill -HUP $MAINPID" in text and "MemoryMax=" in text
    examples = [line.lstrip("# ").strip() for line in text.splitlines() if "LoadCredential=" in line]
    assert examples
    creds = tmp_path / "crisgeo-creds.service"
    creds.write_text(unit.read_text().replace("[Service]\n", "[Service]\n" + "\n".join(examples) + "\n"))
    r = _verify(creds)
    assert r.returncode == 0 and r.stderr.strip() == "", r.stderr


def test_a_reload_puts_the_new_configuration_in_force_and_keeps_the_old_one_if_bad(tmp_path):
    """SIGHUP (systemctl reload): a good file is in force for the next runs; a bad one is refused in the log,
    naming the key, and the daemon goes on with the one in force."""
    empty = tmp_path / "empty"
    empty.mkdir()
    cfg = _config(tmp_path, empty)
    log = tmp_path / "daemon.log"
    with open(log, "w") as fh:
        p = subprocess.Popen(
            CRISGEO + ["daemon", "--config", str(cfg), "--listen", "off"], cwd=ROOT, stdout=fh, stderr=fh
        )
    try:
        assert wait_for(lambda: "crisgeo daemon started" in log.read_text(), 60), log.read_text()
        cfg.write_text(
            cfg.read_text().replace(
                "schedule: {catch_up_days: 2}", "schedule: {catch_up_days: 2, time_utc: '05:45'}"
            )
        )
        p.send_signal(signal.SIGHUP)
        assert wait_for(lambda: "daily at 05:45 UTC" in log.read_text(), 30), log.read_text()
        good = cfg.read_text()
        cfg.write_text(good.replace("time_utc: '05:45'", "time_utc: '25:99'"))
        p.send_signal(signal.SIGHUP)
        assert wait_for(lambda: "the configuration in force is kept" in log.read_text(), 30), log.read_text()
        refused = [line for line in log.read_text().splitlines() if "in force is kept" in line]
        assert "schedule.time_utc" in refused[0] and "ERROR" in refused[0]
        assert p.poll() is None  # still running, on the configuration it had
        p.send_signal(signal.SIGTERM)
        assert p.wait(timeout=30) == 128 + signal.SIGTERM
    finally:
        if p.poll() is None:
            p.kill()


def test_a_secret_comes_from_a_systemd_credential_when_the_environment_has_none(tmp_path, monkeypatch):
    from monitor.config.keys import env_secret

    creds = tmp_path / "creds"
    creds.mkdir()
    (creds / "SMTP_PASSWORD").write_text("s3cret\n")
    monkeypatch.setenv("CREDENTIALS_DIRECTORY", str(creds))
    monkeypatch.delenv("SMTP_PASSWORD", raising=False)
    assert env_secret("SMTP_PASSWORD") == "s3cret"
    monkeypatch.setenv("SMTP_PASSWORD", "from-env")
    assert env_secret("SMTP_PASSWORD") == "from-env"  # the environment first
    assert env_secret("MISSING") is None and env_secret("../creds/SMTP_PASSWORD") is None


@pytest.mark.skipif(
    shutil.which("logrotate") is None, reason="logrotate not installed (Debian package logrotate)"
)
def test_the_alert_log_rotates_and_the_next_message_starts_a_new_file(tmp_path):
    from alerts.channels import LogChannel

    shipped = (ROOT / "systemd" / "crisgeo.logrotate").read_text()
    alert_log = tmp_path / "alerts.log"
    conf = tmp_path / "crisgeo.logrotate"
    conf.write_text(shipped.replace("/var/log/crisgeo/alerts.log", str(alert_log)))
    channel = LogChannel(alert_log)
    channel.send(Message("first", "first message", ""))
    r = subprocess.run(
        ["logrotate", "-f", "-s", str(tmp_path / "state"), str(conf)], capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "alerts.log.1").exists() and "first message" in (tmp_path / "alerts.log.1").read_text()
    channel.send(Message("second", "second message", ""))
    assert "second message" in alert_log.read_text() and "first message" not in alert_log.read_text()


@pytest.mark.servers
@pytest.mark.skipif(shutil.which("systemd-analyze") is None, reason="systemd-analyze not installed")
def test_systemd_unit_exposure_is_at_most_2(tmp_path):
    """`systemd-analyze security` rates the unit's sandbox; 10 is unprotected, the shipped unit <= 2.0."""
    unit = tmp_path / "crisgeo.service"
    unit.write_text((ROOT / "systemd" / "crisgeo.service").read_text())
    r = subprocess.run(
        ["systemd-analyze", "security", "--offline=true", "--no-pager", str(unit)],
        capture_output=True,
        text=True,
    )
    m = re.search(r"Overall exposure level for \S+: (\d+\.\d+)", r.stdout)
    assert m, r.stdout + r.stderr
    assert float(m.group(1)) <= 2.0, r.stdout
    loose = tmp_path / "loose.service"
    loose.write_text(
        unit.read_text()
        .replace("SystemCallFilter=", "#SystemCallFilter=")
        .replace("PrivateUsers=yes", "")
        .replace("ProtectProc=invisible", "")
    )
    r = subprocess.run(
        ["systemd-analyze", "security", "--offline=true", "--no-pager", str(loose)],
        capture_output=True,
        text=True,
    )
    assert float(re.search(r"Overall exposure level for \S+: (\d+\.\d+)", r.stdout).group(1)) > 2.0
