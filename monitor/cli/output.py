"""What crisgeo writes on standard output: an assessment as ``assess`` and ``run`` print it, and standard
output that a pipe closed by its reader silences."""

from __future__ import annotations

import datetime as dt
import os
from typing import Any, TextIO

from monitor.core.result import AssessmentResult
from monitor.core.tables import for_table


class PipedOutput:
    """Standard output that a reader closing the pipe (``| head -1``) silences instead of ending the command.

    The exit status stays the one computed: a Nagios check piped into head still says 2.

    Parameters
    ----------
    stream : TextIO
        The stream written to.
    """

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self.gone = False

    def write(self, text: str) -> int:
        if not self.gone:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self._close()
        return len(text)

    def flush(self) -> None:
        if not self.gone:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._close()

    def _close(self) -> None:
        self.gone = True
        # the interpreter flushes stdout once more at exit: what is left goes to /dev/null, not to a
        # "BrokenPipeError ignored" and exit status 120
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, self._stream.fileno())
        os.close(null)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def utc_text(iso: str) -> str:
    """A time as the service prints every time: ``2026-11-25T03:30:01Z`` (UTC, to the second).

    Parameters
    ----------
    iso : str
        An ISO 8601 time (UTC where it names no zone).

    Returns
    -------
    str
        The time, or the text as given where it is not one.
    """
    try:
        when = dt.datetime.fromisoformat(iso.replace("Z", "+00:00"))
    except ValueError:
        return iso
    when = when.replace(tzinfo=dt.timezone.utc) if when.tzinfo is None else when.astimezone(dt.timezone.utc)
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


def result_text(result: AssessmentResult) -> str:
    """What ``crisgeo assess`` and ``crisgeo run`` print of an assessment.

    Parameters
    ----------
    result : AssessmentResult
        The assessment.

    Returns
    -------
    str
        Its time span, the per-FOR table and its notes.
    """
    who = f"{result.satellite} " if result.satellite else ""
    span = f"{utc_text(result.start)} .. {utc_text(result.end)}" if result.start else "time range unknown"
    lines = [f"{who}{span}, {len(result.granules)} granules"]
    lines += for_table(result.fors)
    # a granule's reason names its file already (FILE: FIELD: REASON): the file once
    lines += [
        f"skipped {s.reason if s.item in s.reason else f'{s.item}: {s.reason}'}" for s in result.skipped
    ]
    lines += [f"note: {n}" for n in result.notes]  # e.g. why the km columns are empty (nan)
    return "\n".join(lines)
