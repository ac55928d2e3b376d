"""One crisgeo process per state directory: the daemon, a run or a reprocessing each hold its lock."""

from __future__ import annotations

import fcntl
import os
from pathlib import Path
from typing import IO


class AlreadyRunning(RuntimeError):
    """Another crisgeo process holds the state directory's lock."""


class InstanceLock:
    """An exclusive flock on ``state_dir/crisgeo.lock``, held for the life of the process."""

    def __init__(self, state_dir: Path):
        self.path = Path(state_dir) / "crisgeo.lock"
        self.fh: IO[str] | None = None

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.fh = open(self.path, "a+")
        try:
            fcntl.flock(self.fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self.fh.seek(0)
            holder = self.fh.read().strip()[:20] or "?"
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
        self.fh.seek(0)
        self.fh.truncate()
        self.fh.write(str(os.getpid()))
        self.fh.flush()
        return self

    def __exit__(self, *exc):
        fcntl.flock(self.fh, fcntl.LOCK_UN)
        self.fh.close()
