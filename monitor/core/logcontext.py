"""The satellite-day a log line belongs to: fields (``satellite``, ``day``, ``stage``, ``run_id``) that
the work sets around itself and that the service's JSON lines carry (:mod:`monitor.service.logs`).

It lives on the ground floor because the day's driver (:mod:`monitor.assessment.day`) names its stages
and the service formats the lines: neither imports the other for it.
"""

from __future__ import annotations

import contextvars
from collections.abc import Iterator
from contextlib import contextmanager

_context: contextvars.ContextVar[dict | None] = contextvars.ContextVar("crisgeo_log_context", default=None)


def fields() -> dict:
    """The fields of the block under way.

    Returns
    -------
    dict
        Satellite, day, stage, run_id; empty outside a block.
    """
    return _context.get() or {}


@contextmanager
def context(**new: object) -> Iterator[None]:
    """Add fields to every line logged inside the block.

    Parameters
    ----------
    **new : object
        Fields: satellite, day, stage, run_id.

    Returns
    -------
    iterator
        A context manager's one value, None.
    """
    token = _context.set({**fields(), **{k: v for k, v in new.items() if v is not None}})
    try:
        yield
    finally:
        _context.reset(token)


def stage(name: str) -> None:
    """Name the stage of the satellite-day under way.

    Only inside :func:`context`, which ends it: outside one the name would stay on every later line of the
    thread.

    Parameters
    ----------
    name : str
        The stage.
    """
    if _context.get() is None:
        raise RuntimeError("logcontext.stage outside logcontext.context")
    _context.set({**fields(), "stage": name})
