"""crisgeo-monitor: CrIS geolocation assessment against VIIRS I5 (Wang et al. 2017), run as a service.

The folders are the floors, each importing only those below it (docs/layout.md): ``cli``, ``service``, the
science (``assessment``, ``mapping`` and ``simulate``, ``collocation`` and ``estimation``, ``instrument``,
``sdr``, ``geometry``), ``config`` and the ground floor ``core``. The science hands the service one typed
object, :class:`monitor.core.result.AssessmentResult`.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from monitor.version import __version__

if TYPE_CHECKING:
    from monitor.service.outputs.export import ResultStore

__all__ = ["AssessmentResult", "assess_paths", "open_store", "__version__"]


def __getattr__(name: str) -> Any:  # the public API, imported when first used (a light import)
    if name == "assess_paths":
        from monitor.assessment.assess import assess_paths

        return assess_paths
    if name == "AssessmentResult":
        from monitor.core.result import AssessmentResult

        return AssessmentResult
    if name == "open_store":
        return open_store
    raise AttributeError(f"module 'monitor' has no attribute {name!r}")


def open_store(path: str | os.PathLike, create: bool = False) -> ResultStore:
    """The service's SQLite store, for a notebook: ``open_store(p).to_xarray("j01")``.

    Parameters
    ----------
    path : str or os.PathLike
        The store (``store.sqlite``; the demo's ``demo-state/crisgeo.sqlite``).
    create : bool, optional
        Make a new store; otherwise a missing one is an error (a typo must not start an empty history).

    Returns
    -------
    ResultStore
        The store; a context manager that closes it.
    """
    from monitor.service.outputs.export import ResultStore
    from monitor.service.store.sqlite import Store

    return ResultStore(Store(path, create=create))
