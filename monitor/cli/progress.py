"""Progress of a long command, with its total: a bar on a terminal, log lines elsewhere (the journal).

``assess``, ``simulate`` and ``run`` count granules; ``reprocess`` counts satellite-days the same way. Off a
terminal a line at most every 30 s and one at the end (``assessing granules: 5/14 after 62 s``), as the
daily run's own lines are.
"""

from __future__ import annotations

import logging
import sys
import time
from types import TracebackType

LOG = logging.getLogger("monitor.cli")


class Progress:
    """Count items done against a total that may grow (the daily run learns each batch's size as it comes).

    Parameters
    ----------
    what : str
        What is counted (``assessing granules``).
    total : int, optional
        The items known now.
    every_s : float, optional
        Seconds between log lines at most, off a terminal.
    """

    def __init__(self, what: str, total: int = 0, every_s: float = 30.0) -> None:
        self.what, self.total, self.every_s = what, total, every_s
        self.done = 0
        self.t0 = self.last = time.monotonic()
        self.bar = None
        if sys.stderr.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total or None, desc=what, unit="granule")

    def begin(self, more: int) -> None:
        """Add *more* items to the total (a batch about to be assessed).

        Parameters
        ----------
        more : int
            Items.
        """
        self.total += more
        if self.bar is not None:
            self.bar.total = self.total
            self.bar.refresh()

    def __call__(self, _item: object = None) -> None:
        self.done += 1
        if self.bar is not None:
            self.bar.update(1)
            return
        now = time.monotonic()
        if self.done >= self.total or now - self.last >= self.every_s:
            self.last = now
            LOG.info("%s: %d/%d after %.0f s", self.what, self.done, self.total, now - self.t0)

    def __enter__(self) -> Progress:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        if self.bar is not None:
            self.bar.close()
