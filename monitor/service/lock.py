"""One crisgeo process per state directory: the daemon, a run or a reprocessing each hold its lock.

The lock file holds the holder's pid and role (``daemon``, ``run``, ``reprocess``); :func:`holder` asks the
kernel's lock table (``/proc/locks``) whether that lock is still held, without taking it (a ``crisgeo
status`` every few minutes must never stand in the daemon's way).
"""

from __future__ import annotations

import contextlib
import fcntl
import os
from pathlib import Path
from typing import IO


class AlreadyRunning(RuntimeError):
    """Another crisgeo process holds the state directory's lock."""


class InstanceLock:
    """An exclusive flock on ``state_dir/crisgeo.lock``, held for the life of the process.

    Parameters
    ----------
    state_dir : Path
        The state directory.
    role : str
        What holds it (``daemon``, ``run``, ``reprocess``), written into the lock file.
    """

    def __init__(self, state_dir: Path, role: str):
        self.path = Path(state_dir) / "crisgeo.lock"
        self.role = role
        self.fh: IO[str] | None = None

    def __enter__(self) -> InstanceLock:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.fh = open(self.path, "a+")
        try:
            fcntl.flock(self.fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self.fh.seek(0)
            holder = self.fh.read().split(" ")[0][:20] or "?"
            self.fh.close()
            raise AlreadyRunning(
                f"{self.path}: another crisgeo process (pid {holder}) is running on this state directory. "
                "The "
                "daemon assesses the missed days of its catch-up window itself at its next daily run; to "
                "redo "
                "a day now, stop it (systemctl stop crisgeo), run 'crisgeo run --date YYYY-MM-DD', and "
                "start "
                f"it again"
            ) from None
        try:
            self.fh.seek(0)
            self.fh.truncate()
            self.fh.write(f"{os.getpid()} {self.role}")
            self.fh.flush()
        except OSError as exc:  # a full disk: named, and the lock let go
            fcntl.flock(self.fh, fcntl.LOCK_UN)
            with contextlib.suppress(OSError):  # closing flushes the same bytes again
                self.fh.close()
            raise OSError(exc.errno, exc.strerror, str(self.path)) from None
        return self

    def __exit__(self, *exc: object) -> None:
        assert self.fh is not None, "entered"
        fcntl.flock(self.fh, fcntl.LOCK_UN)
        self.fh.close()


def holder(state_dir: Path, role: str) -> int | None:
    """The pid of the process of *role* holding *state_dir*'s lock, None when none does.

    Parameters
    ----------
    state_dir : Path
        The state directory.
    role : str
        The role asking.

    Returns
    -------
    int or None
        The pid of the process of *role* holding the lock; None when none does.
    """
    path = Path(state_dir) / "crisgeo.lock"
    try:
        inode = path.stat().st_ino
        pid, _, held_as = path.read_text().partition(" ")
        table = Path("/proc/locks").read_text()
    except (OSError, ValueError):
        return None
    if held_as.strip() != role:
        return None
    for line in table.splitlines():  # "1: FLOCK ADVISORY WRITE <pid> <maj>:<min>:<inode> 0 EOF"
        fields = line.split()
        if "FLOCK" in fields and "->" not in fields and fields[-3].endswith(f":{inode}"):
            return int(fields[-4]) if fields[-4] == pid else None
    return None
