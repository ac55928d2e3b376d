"""Pairing: of several copies of a granule the newest that reads is used, and every copy left out is named
with why."""

import re
import shutil

import h5py
import numpy as np

from monitor.sdr.pairing import plan
from monitor.sdr.products import PRODUCTS


def _newer_copy(src, folder):
    """A reprocessed copy of *src* in *folder*: the same granule, a later creation time."""
    dst = folder / re.sub(r"_c\d+", "_c20991231235959000000", src.name)
    shutil.copyfile(src, dst)
    return dst


def _set(path, field, fn):
    with h5py.File(path, "r+") as h5:
        name = f"{PRODUCTS['GCRSO'].data_group}/{field}"
        h5[name][...] = fn(h5[name][()])


def _linked(base, folder):
    for f in base.glob("*.h5"):
        (folder / f.name).symlink_to(f)
    return sorted(base.glob("GCRSO_*.h5"))[0]


def test_a_corrupt_newer_copy_is_named_and_the_older_one_used(cases, tmp_path):
    base, _, _ = cases.get()
    original = _linked(base, tmp_path)
    newer = _newer_copy(original, tmp_path)
    _set(newer, "FORTime", np.zeros_like)
    result = plan([tmp_path])
    used = [g for g in result.cris_all if g.geo.name in (original.name, newer.name)]
    assert [g.geo.name for g in used] == [original.name]
    reasons = dict(result.skipped)
    assert newer.name in reasons[str(newer)] and "FORTime" in reasons[str(newer)]
    assert "an older copy of the granule is tried" in reasons[str(newer)]


def test_a_readable_newer_copy_replaces_the_older_one_and_says_so(cases, tmp_path):
    base, _, _ = cases.get()
    original = _linked(base, tmp_path)
    newer = _newer_copy(original, tmp_path)
    _set(newer, "SCAttitude", lambda a: a + np.float32(0.01))  # a reprocessing that changed the attitude
    result = plan([tmp_path])
    used = [g for g in result.cris_all if g.geo.name in (original.name, newer.name)]
    assert [g.geo.name for g in used] == [newer.name]
    reasons = dict(result.skipped)
    assert reasons[str(tmp_path / original.name)].endswith(f"{newer.name} is used")
    assert len(result.skipped) == 1
