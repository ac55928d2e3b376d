"""The version of the installed distribution: pyproject.toml's, the one place it is written."""

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _dist_version

try:
    __version__ = _dist_version("crisgeo-monitor")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
