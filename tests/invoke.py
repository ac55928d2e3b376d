"""Running the crisgeo command as an operator does: a child process of this interpreter, from the checkout."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CRISGEO = [sys.executable, "-m", "monitor.cli"]


def run_crisgeo(*args, env: dict | None = None, timeout: float = 600) -> subprocess.CompletedProcess:
    """``crisgeo ARGS`` run to its end, stdout and stderr captured as text; *env* replaces the environment
    when given. A command that outlives *timeout* seconds fails the test instead of hanging it."""
    return subprocess.run(
        [*CRISGEO, *map(str, args)], capture_output=True, text=True, cwd=ROOT, env=env, timeout=timeout
    )
