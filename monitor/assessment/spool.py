"""A day's collocated samples kept on disk while the day grows, read back one FOR at a time.

A granule's VIIRS BT through every perturbed cone and, with the footprint kernel, its radiance per annulus
(twice that with the rendered collocation of the parallax correction) would, over a long day, outgrow the
memory a day may have (docs/performance.md). The estimate needs them one FOR at a time (a thirtieth of each
granule), so a :class:`DayAssessment <monitor.assessment.assess.DayAssessment>` writes each granule's arrays
to a temporary directory as it is collocated, and each read maps the file, copies the slice asked for and
unmaps it: resident memory holds one FOR of the day, not the day. While the day's lift is sought, each FOR's
samples, once built, wait here too (:meth:`Spool.parked`). The directory is made with :mod:`tempfile`
(``TMPDIR``; it should be on disk, not a RAM disk) and removed when the day is done or the process exits.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from monitor.core.errors import AssessmentError
from monitor.estimation.estimate import ForSamples


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

    def parked(self, s: ForSamples) -> Callable[[], ForSamples]:
        """A FOR's samples with their surfaces (and annuli) written to the spool: the day's lift is sought
        before any FOR is estimated at it, and the FORs wait here meanwhile, out of memory.

        Parameters
        ----------
        s : ForSamples
            One FOR's samples, built.

        Returns
        -------
        callable
            Reads the same samples back into memory, whole, when called.
        """
        surface = self.keep(s.d_k)
        annuli = None if s.annuli_rad is None else self.keep(s.annuli_rad)
        light = replace(s, d_k=np.empty((0,)), annuli_rad=None)

        def back() -> ForSamples:
            return replace(light, d_k=surface[...], annuli_rad=None if annuli is None else annuli[...])

        return back

    def close(self) -> None:
        """Remove the directory and every array in it."""
        self._dir.cleanup()
