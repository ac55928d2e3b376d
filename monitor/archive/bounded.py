"""HTTP whose every request ends by a wall-clock deadline, the response body included.

urllib3's timeouts bound each socket operation, not a request: a server that sends one byte a second
never trips a 60 s read timeout, and a 420-byte listing page then takes seven minutes. Here every
connection the session opens is remembered, and a watchdog timer shuts the sockets down when the
deadline of the request under way passes; the blocked read returns at once with an error, which
:meth:`BoundedSession.guard` turns into the caller's message.

Downloads are also watched for stalls by :class:`StallWatch`: over any sliding window of
``window_s`` seconds at least ``min_rate`` bytes per second must arrive (a total budget per attempt,
as before, let a one-byte-a-second GITCO run for 40 minutes).
"""

from __future__ import annotations

import collections
import socket
import threading
import time
import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import requests
import urllib3
from requests.adapters import HTTPAdapter


class DeadlinePassed(Exception):
    """The watchdog cut the request: its deadline passed."""


def _tracked(
    connection_cls: type[urllib3.connection.HTTPConnection], sockets: weakref.WeakSet
) -> type[urllib3.connection.HTTPConnection]:
    """A urllib3 connection class that records every socket it opens in *sockets*."""

    def connect(self: urllib3.connection.HTTPConnection) -> None:
        connection_cls.connect(self)
        sockets.add(self.sock)

    return type("Tracked", (connection_cls,), {"connect": connect})


class _TrackingAdapter(HTTPAdapter):
    def __init__(self, sockets: weakref.WeakSet) -> None:
        self._sockets = sockets
        super().__init__(max_retries=0)  # the one retry layer is the caller's

    def init_poolmanager(self, *args: Any, **kwargs: Any) -> None:
        super().init_poolmanager(*args, **kwargs)
        http = _tracked(urllib3.connection.HTTPConnection, self._sockets)
        https = _tracked(urllib3.connection.HTTPSConnection, self._sockets)
        self.poolmanager.pool_classes_by_scheme = {
            "http": type("Pool", (urllib3.HTTPConnectionPool,), {"ConnectionCls": http}),
            "https": type("Pool", (urllib3.HTTPSConnectionPool,), {"ConnectionCls": https}),
        }


class BoundedSession:
    """A :class:`requests.Session` (identity encoding, no redirects followed by itself, no retries)
    whose requests a watchdog can cut at a deadline."""

    def __init__(self) -> None:
        self._sockets: weakref.WeakSet = weakref.WeakSet()
        self.session = requests.Session()
        adapter = _TrackingAdapter(self._sockets)
        self.session.mount("http://", adapter)
        self.session.mount("https://", adapter)
        self.session.headers["Accept-Encoding"] = "identity"

    def _cut(self, fired: threading.Event) -> None:
        fired.set()
        for s in list(self._sockets):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass  # already closed

    @contextmanager
    def guard(self, deadline: float) -> Iterator[None]:
        """Run the block under a watchdog: at ``time.monotonic() == deadline`` every socket of the
        session is shut down, and whatever the block then raises becomes :class:`DeadlinePassed`.

        Parameters
        ----------
        deadline : float
            The ``time.monotonic()`` s at which every socket of the session is shut down.

        Returns
        -------
        iterator
            A context manager's one value, None.
        """
        fired = threading.Event()
        timer = threading.Timer(max(0.0, deadline - time.monotonic()), self._cut, (fired,))
        timer.daemon = True
        timer.start()
        try:
            yield
        except Exception as exc:
            if fired.is_set():
                raise DeadlinePassed from exc
            raise
        finally:
            timer.cancel()
        if fired.is_set():
            raise DeadlinePassed

    def get(self, url: str, **kwargs: Any) -> requests.Response:
        """A plain GET on the session (call it under :meth:`guard`).

        Parameters
        ----------
        url : str
            The URL.
        **kwargs : object
            ``requests``' keywords.

        Returns
        -------
        requests.Response
            The response.
        """
        return self.session.get(url, allow_redirects=False, **kwargs)


class StallWatch:
    """Progress of one transfer against a minimum rate over a sliding window.

    :meth:`stalled` is true once the transfer has run for at least *window_s* and the bytes of the
    last *window_s* seconds are fewer than ``min_rate_b_s * window_s``.

    Parameters
    ----------
    min_rate_b_s : float
        The least rate, bytes per s, over a window.
    window_s : float
        The window, s.
    clock : callable, optional
        The clock, s (``time.monotonic``).
    """

    def __init__(
        self, min_rate_b_s: float, window_s: float, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.min_bytes = min_rate_b_s * window_s
        self.window_s = window_s
        self.clock = clock
        self.t0 = clock()
        self.total = 0
        self._marks: collections.deque = collections.deque([(self.t0, 0)])

    def add(self, n: int) -> None:
        """Count *n* bytes received now.

        Parameters
        ----------
        n : int
            Bytes received now.
        """
        self.total += n
        now = self.clock()
        self._marks.append((now, self.total))
        # keep one mark at or before the window's start, so the window's count is exact
        while len(self._marks) > 2 and self._marks[1][0] <= now - self.window_s:
            self._marks.popleft()

    def stalled(self) -> bool:
        """Fewer bytes than the minimum rate asks for over the last window.

        Returns
        -------
        bool
            True when the rate over the last window is below the minimum.
        """
        now = self.clock()
        if now - self.t0 < self.window_s:
            return False
        since = now - self.window_s
        base = self._marks[0][1]
        for t, n in self._marks:
            if t <= since:
                base = n
        return self.total - base < self.min_bytes
