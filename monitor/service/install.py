"""The files a deployment needs besides the program, as shipped in the package (``monitor/shipped``):
the example configuration and events calendar, the EP files, the Grafana dashboard and provisioning,
the Prometheus alerting rules, the systemd unit, the README and docs/.

In a source tree ``monitor/shipped`` links to the top-level ``configs/``, ``systemd/``, ``docs/`` and
``README.md``; the wheel carries copies. ``importlib.resources.files("monitor") / "shipped"`` is their
place in an installation; ``crisgeo install-files DEST`` copies them out.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterator
from importlib.abc import Traversable
from importlib.resources import as_file, files
from pathlib import Path

from monitor.core.constants import SPEC_KM
from monitor.service.outputs.dashboards import with_specification

DASHBOARDS = ("configs", "grafana")  # the folder of the Grafana dashboards, rendered at the specification


def shipped_root() -> Traversable:
    """The shipped files (an importlib.resources Traversable).

    Returns
    -------
    importlib.abc.Traversable
        ``monitor/shipped``.
    """
    return files("monitor") / "shipped"


def _walk(node: Traversable, rel: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], Traversable]]:
    for child in sorted(node.iterdir(), key=lambda c: c.name):
        if child.name.startswith(".") or child.name == "__pycache__":
            continue
        if child.is_dir():
            yield from _walk(child, rel + (child.name,))
        else:
            yield rel + (child.name,), child


def install_files(dest: str | Path, force: bool = False, spec_km: float = SPEC_KM) -> list[Path]:
    """Copy every shipped file under *dest* (same tree: configs/, systemd/, docs/, README.md).

    Parameters
    ----------
    dest : str or Path
        The directory to copy into.
    force : bool, optional
        Replace files that exist; else an existing file is left alone (it may be an operator's edited
        configuration).
    spec_km : float, optional
        The specification (km, ``alerts.spec_km``) the Grafana dashboards' thresholds are written at
        (:func:`monitor.service.outputs.dashboards.with_specification`).

    Returns
    -------
    list of Path
        The files written.
    """
    dest = Path(dest)
    written = []
    for rel, node in _walk(shipped_root()):
        target = dest.joinpath(*rel)
        if target.exists() and not force:
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        dashboard = rel[:-1] == DASHBOARDS and rel[-1].endswith(".json")
        shipped = json.loads(node.read_text()) if dashboard else None
        if shipped is not None and with_specification(shipped, spec_km) != shipped:
            target.write_text(json.dumps(with_specification(shipped, spec_km), indent=1) + "\n")
        else:  # as shipped, byte for byte
            with as_file(node) as src:
                shutil.copyfile(src, target)
        written.append(target)
    return written


def kept_files(dest: str | Path) -> list[Path]:
    """The shipped files that already exist under *dest* (what :func:`install_files` leaves alone).

    Parameters
    ----------
    dest : str or Path
        The target directory.

    Returns
    -------
    list of Path
        The shipped files that already exist under it.
    """
    dest = Path(dest)
    return [dest.joinpath(*rel) for rel, _ in _walk(shipped_root()) if dest.joinpath(*rel).exists()]
