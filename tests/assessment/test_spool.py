"""The day's samples on disk: read back exactly, one slice at a time, and removed when the day is done."""

import numpy as np
import pytest

from monitor.assessment.spool import OnDisk, Spool
from monitor.core.errors import AssessmentError


def test_on_disk_gives_back_the_slice_asked_for():
    rng = np.random.default_rng(3)
    array = rng.normal(size=(4, 30, 9, 4, 5, 5)).astype(np.float32)
    spool = Spool()
    kept = spool.keep(array)
    assert isinstance(kept, OnDisk) and kept.shape == array.shape
    got = kept[:, 7]
    assert isinstance(got, np.ndarray) and not isinstance(got, np.memmap)  # a copy, not a map
    assert np.array_equal(got, array[:, 7]) and got.dtype == np.float32
    assert np.array_equal(kept[...], array)
    spool.close()
    assert not kept.path.exists() and not kept.path.parent.exists()


def test_a_spool_that_cannot_write_names_the_file():
    spool = Spool()
    spool.close()  # its directory is gone: the disk refuses
    with pytest.raises(AssessmentError, match=r"crisgeo-day-.*000000\.npy: cannot keep"):
        spool.keep(np.zeros(3))
