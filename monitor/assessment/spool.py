"""A day's collocated samples kept on disk while the day grows, read back one FOR at a time.

A granule's VIIRS BT through every perturbed cone and, with the footprint kernel, its radiance per annulus
take ~9.5 MB, twice that with the rendered collocation of the parallax correction: ~1.9 GB for a day of 100
granules if they stayed in memory. The estimate needs them one FOR at a time (a thirtieth of each granule),
so a :class:`DayAssessment <monitor.assessment.assess.DayAssessment>` writes each granule's arrays to a
temporary directory as it is collocated, and each read maps the file, copies the slice asked for and unmaps
it: resident memory holds one FOR of the day, not the day. The directory is made with :mod:`tempfile`
(``TMPDIR``; it should be on disk, not a RAM disk) and removed when the day is done or the process exits.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from monitor.core.errors import AssessmentError


@dataclass(frozen=True)
class OnDisk:
    """An array in a ``.npy`` file: indexing it reads only the slice asked for, as a new in-memory array."""

    path: Path
    shape: tuple[int, ...]

    def __getitem__(self, index: Any) -> np.ndarray:
        mapped = np.load(self.path, mmap_mode="r")
        return np.array(mapped[index])  # a copy: the map is released with *mapped*


class Spool:
    """A temporary directory holding arrays (:meth:`keep`) until :meth:`close` or the process's exit."""

    def __init__(self) -> None:
        self._dir = tempfile.TemporaryDirectory(prefix="crisgeo-day-")
        self._count = 0

    def keep(self, array: np.ndarray) -> OnDisk:
        """An array written to the spool.

        Parameters
        ----------
        array : numpy.ndarray
            The array.

        Returns
        -------
        OnDisk
            It, on disk; an :class:`AssessmentError` naming the file if the disk refuses.
        """
        path = Path(self._dir.name) / f"{self._count:06d}.npy"
        self._count += 1
        try:
            np.save(path, array)
        except OSError as exc:
            raise AssessmentError(f"{path}: cannot keep the day's collocated samples on disk: {exc}") from exc
        return OnDisk(path, array.shape)

    def close(self) -> None:
        """Remove the directory and every array in it."""
        self._dir.cleanup()
