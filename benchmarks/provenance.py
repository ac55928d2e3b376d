"""Where a result row was measured: the commit of the code that printed it (``-dirty`` when the work tree
held changes: such a row backs no figure)."""

from __future__ import annotations

import subprocess
from functools import cache
from pathlib import Path


@cache
def commit() -> str:
    """``git describe --always --dirty`` of this checkout, or ``unknown`` outside one."""
    done = subprocess.run(
        ["git", "describe", "--always", "--dirty"],
        capture_output=True,
        text=True,
        cwd=Path(__file__).parent,
    )
    return done.stdout.strip() or "unknown"


def emit(row: dict, rows_path: str | None) -> None:
    """Print one JSON result row, and append it to *rows_path* when given."""
    import json

    print(json.dumps(row), flush=True)
    if rows_path:
        with open(rows_path, "a") as fh:
            fh.write(json.dumps(row) + "\n")
