"""A full disk: a day that finds too little room is not begun; a day that fills the disk mid-run ends in
one line naming the cause, leaves no half-simulated day and a consistent store; both are redone once there
is room. The file system is real: a tmpfs of a few MB mounted for the test (root only)."""

import datetime as dt
import subprocess

import pytest

from monitor.core.vocabulary import RunStatus
from monitor.service.store.sqlite import Store
from tests.invoke import run_crisgeo

pytestmark = pytest.mark.servers  # mounts a file system and runs the daily job (see pyproject markers)

DAY = "2024-06-01"


@pytest.fixture
def small_disk(tmp_path):
    """A tmpfs of 24 MB at tmp_path/small; its size can be changed with remount(size_mb)."""
    mount = tmp_path / "small"
    mount.mkdir()
    made = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=24m", "tmpfs", str(mount)], capture_output=True
    )
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.decode().strip()}")

    def remount(size_mb: int) -> None:
        subprocess.run(["mount", "-o", f"remount,size={size_mb}m", str(mount)], check=True)

    yield mount, remount
    subprocess.run(["umount", "-l", str(mount)], check=False)


def _config(tmp_path, state, min_free_mb):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {state}\nmin_free_mb: {min_free_mb}\n"
        "source: {kind: simulated, granules: 2}\nschedule: {catch_up_days: 1}\n"
        f"alerts: {{log: {tmp_path / 'alerts.log'}}}\n"
    )
    return cfg


def _runs(db):
    with Store(db) as s:
        return [(r.status, r.reason or "") for r in s.runs("j01")]


def test_a_day_without_room_is_not_begun_and_is_redone_once_there_is(small_disk, tmp_path):
    mount, remount = small_disk
    cfg = _config(tmp_path, mount / "state", min_free_mb=100)
    r = run_crisgeo("run", "--config", cfg, "--date", DAY, timeout=300)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    ((status, reason),) = _runs(mount / "state" / "crisgeo.sqlite")
    assert status == RunStatus.FAILED and reason.startswith(f"no room: {mount / 'state'}: "), reason
    assert "a day needs min_free_mb 100" in reason and not list((mount / "state").rglob("*.h5"))
    remount(1000)
    r = run_crisgeo("run", "--config", cfg, "--date", DAY, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    assert [s for s, _ in _runs(mount / "state" / "crisgeo.sqlite")] == [RunStatus.FAILED, RunStatus.OK]


def test_a_disk_filled_mid_run_ends_in_one_line_and_keeps_the_store(small_disk, tmp_path):
    mount, remount = small_disk
    cfg = _config(tmp_path, mount / "state", min_free_mb=0)  # let it start: the simulation fills the disk
    r = run_crisgeo("run", "--config", cfg, "--date", DAY, timeout=300)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    db = mount / "state" / "crisgeo.sqlite"
    ((status, reason),) = _runs(db)
    assert status == RunStatus.FAILED and "No space left on device" in reason, reason
    assert not list((mount / "state").rglob(DAY)), "a half-simulated day was left behind"
    with Store(db) as s:
        assert s.integrity() == "ok"
        assert s.latest_day("j01") is None
    remount(1000)
    r = run_crisgeo("run", "--config", cfg, "--date", DAY, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    with Store(db) as s:
        assert (
            s.latest_day("j01") == dt.date.fromisoformat(DAY)
            and len(s.day_result("j01", s.latest_day("j01"))) == 30
        )


def test_a_store_that_cannot_be_written_is_one_line_naming_it(small_disk, tmp_path):
    mount, _ = small_disk
    cfg = _config(tmp_path, mount / "state", min_free_mb=0)
    assert run_crisgeo("check-config", "--config", cfg).returncode == 0
    (mount / "state").mkdir()
    with Store(mount / "state" / "crisgeo.sqlite"):
        pass
    with open(mount / "filler", "wb") as fh:  # every byte of the file system taken
        try:
            while True:
                fh.write(b"\0" * (1 << 20))
                fh.flush()
        except OSError:
            pass
    r = run_crisgeo("run", "--config", cfg, "--date", DAY, timeout=300)
    lines = [line for line in r.stderr.splitlines() if line.startswith("crisgeo run:")]
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    assert len(lines) == 1 and str(mount / "state") in lines[0], r.stderr
    assert "No space left on device" in lines[0] or "no room left" in lines[0], r.stderr
