"""The source a configuration names (``source.kind``): the one place that knows every kind."""

from __future__ import annotations

from pathlib import Path

from monitor.archive import Source
from monitor.archive.local import LocalSource, SimulatedSource
from monitor.archive.nodd import NoddSource
from monitor.config.model import Config


def make_source(cfg: Config) -> Source:
    """The source named by the configuration's ``source.kind``.

    Parameters
    ----------
    cfg : Config
        The configuration.

    Returns
    -------
    Source
        A local, simulated or NODD source.
    """
    kind = cfg.source.kind
    if kind == "local":
        assert cfg.source.path is not None, "the configuration requires a path for a local source"
        return LocalSource(cfg.source.path)
    if kind == "simulated":
        return SimulatedSource(cfg.state_dir / "simulated", cfg.source, cfg.viirs_bands)
    return NoddSource(cfg.source, Path(cfg.cache_dir))
