"""crisgeo-monitor: CrIS geolocation assessment against VIIRS I5 (Wang et al. 2017), run as a service.

The science lives in ``monitor.sdr`` (files), ``monitor.geometry`` (frames), ``monitor.spectral``,
``monitor.collocate``, ``monitor.assess`` and ``monitor.simulate``; it hands the service one typed
object, :class:`monitor.result.AssessmentResult`.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from monitor.version import __version__

if TYPE_CHECKING:
    from monitor.store.sqlite import Store

__all__ = ["AssessmentResult", "assess_paths", "open_store", "__version__"]


def __getattr__(name: str) -> Any:  # the public API, imported when first used (a light import)
    if name == "assess_paths":
        from monitor.assess import assess_paths

        return assess_paths
    if name == "AssessmentResult":
        from monitor.result import AssessmentResult

        return AssessmentResult
    if name == "open_store":
        return open_store
    raise AttributeError(f"module 'monitor' has no attribute {name!r}")


def open_store(path: str | os.PathLike, create: bool = False) -> Store:
    """The service's SQLite store at *path*, e.g. ``open_store(p).to_xarray("j01")`` in a notebook. A
    missing store is an error (a typo must not start an empty history) unless *create*."""
    from monitor.store.sqlite import Store

    return Store(path, create=create)
