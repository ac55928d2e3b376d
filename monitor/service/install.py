"""The files a deployment needs besides the program, as shipped in the package (``monitor/shipped``):
the example configuration and events calendar, the EP files, the Grafana dashboard and provisioning,
the Prometheus alerting rules, the systemd unit, the README and docs/.

In a source tree ``monitor/shipped`` links to the top-level ``configs/``, ``systemd/``, ``docs/`` and
``README.md``; the wheel carries copies. ``importlib.resources.files("monitor") / "shipped"`` is their
place in an installation; ``crisgeo install-files DEST`` copies them out.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from importlib.abc import Traversable
from importlib.resources import as_file, files
from pathlib import Path


def shipped_root() -> Traversable:
    """The shipped files (an importlib.resources Traversable)."""
    return files("monitor") / "shipped"


def _walk(node: Traversable, rel: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], Traversable]]:
    for child in sorted(node.iterdir(), key=lambda c: c.name):
        if child.name.startswith(".") or child.name == "__pycache__":
            continue
        if child.is_dir():
            yield from _walk(child, rel + (child.name,))
        else:
            yield rel + (child.name,), child


def install_files(dest: str | Path, force: bool = False) -> list[Path]:
    """Copy every shipped file under *dest* (same tree: configs/, systemd/, docs/, README.md). An existing
    file is left alone unless *force* (it may be an operator's edited configuration); returns the files
    written."""
    dest = Path(dest)
    written = []
    for rel, node in _walk(shipped_root()):
        target = dest.joinpath(*rel)
        if target.exists() and not force:
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        with as_file(node) as src:
            shutil.copyfile(src, target)
        written.append(target)
    return written


def kept_files(dest: str | Path) -> list[Path]:
    """The shipped files that already exist under *dest* (what :func:`install_files` leaves alone)."""
    dest = Path(dest)
    return [dest.joinpath(*rel) for rel, _ in _walk(shipped_root()) if dest.joinpath(*rel).exists()]
