"""The daemon's health: is the scheduler turning, and is every job within its time budget?

``/healthz`` reports it and the systemd watchdog is fed only while it holds, so a hung download or a
wedged worker (a job past its budget) and a stalled scheduler (no heartbeat) both end in a restart.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager


class Health:
    """Jobs in flight with their budgets, and the scheduler's last heartbeat (monotonic seconds).

    *stall_s*: the scheduler counts as stalled when its heartbeat job has not run for this long.

    Parameters
    ----------
    stall_s : float
        The scheduler counts as stalled when its heartbeat job has not run for this long, s.
    clock : callable, optional
        The clock, s (``time.monotonic``).
    """

    def __init__(self, stall_s: float, clock: Callable[[], float] = time.monotonic) -> None:
        self.stall_s = stall_s
        self.clock = clock
        self._lock = threading.Lock()
        self._jobs: dict[int, tuple[str, float, float]] = {}  # key -> (name, started, budget_s)
        self._next = 0
        self._beat = clock()

    def beat(self) -> None:
        """The scheduler's heartbeat job ran."""
        with self._lock:
            self._beat = self.clock()

    @contextmanager
    def job(self, name: str, budget_s: float) -> Iterator[None]:
        """Track the block as job *name*, unhealthy once it runs longer than *budget_s*.

        Parameters
        ----------
        name : str
            The job.
        budget_s : float
            How long it may take, s.

        Returns
        -------
        iterator
            A context manager's one value, None.
        """
        with self._lock:
            key = self._next
            self._next += 1
            self._jobs[key] = (name, self.clock(), budget_s)
        try:
            yield
        finally:
            with self._lock:
                del self._jobs[key]

    def problems(self) -> list[str]:
        """What is wrong now, one sentence each; empty when healthy.

        Returns
        -------
        list of str
            A stalled scheduler and jobs over their budget; empty when healthy.
        """
        now = self.clock()
        with self._lock:
            jobs = list(self._jobs.values())
            silent = now - self._beat
        out = [
            f"{name}: running for {now - t0:.0f} s, over its budget of {budget:.0f} s"
            for name, t0, budget in jobs
            if now - t0 > budget
        ]
        if silent > self.stall_s:
            out.append(f"scheduler: no heartbeat for {silent:.0f} s (stalled after {self.stall_s:.0f} s)")
        return out

    def running(self) -> list[dict]:
        """The jobs in flight: name, seconds running, budget.

        Returns
        -------
        list of dict
            The jobs in flight, their budgets and how long they have run.
        """
        now = self.clock()
        with self._lock:
            return [
                {"job": n, "running_s": round(now - t0, 1), "budget_s": b} for n, t0, b in self._jobs.values()
            ]
