"""A day's collocated samples kept on disk while the day grows, read back one FOR at a time.

A granule's VIIRS BT through every perturbed cone and, with the footprint kernel, its radiance per annulus
(twice that with the rendered collocation of the parallax correction) would, over a long day, outgrow the
memory a day may have (docs/performance.md). The estimate needs them one FOR at a time (a thirtieth of each
granule), so a :class:`DayAssessment <monitor.assessment.assess.DayAssessment>` writes each granule's arrays
to a temporary directory as it is collocated, and each read maps the file, copies the slice asked for and
unmaps it: resident memory holds one FOR of the day, not the day. While the day's lift is sought, each FOR's
samples, once built, wait here too (:meth:`Spool.kept_samples`). The directory is made with :mod:`tempfile`
(``TMPDIR``; it should be on disk, not a RAM disk) and removed when the day is done or the process exits.
"""

from __future__ import annotations

import tempfile
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

    def kept_samples(self, s: ForSamples) -> ForSamples:
        """A FOR's samples with their surfaces (and annuli) written to the spool and mapped back read-only:
        the day's lift is sought before any FOR is estimated at it, and the FORs wait here meanwhile.

        Parameters
        ----------
        s : ForSamples
            One FOR's samples, built.

        Returns
        -------
        ForSamples
            The same samples, their large arrays read from disk when used.
        """
        annuli = None if s.annuli_rad is None else self._mapped(s.annuli_rad)
        return replace(s, d_k=self._mapped(s.d_k), annuli_rad=annuli)

    def _mapped(self, array: np.ndarray) -> np.ndarray:
        return np.load(self.keep(array).path, mmap_mode="r")

    def close(self) -> None:
        """Remove the directory and every array in it."""
        self._dir.cleanup()
