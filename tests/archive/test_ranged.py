"""Granules read in place from a real S3-compatible server on loopback (moto's server), through the block
cache; faults from the hostile test server (benchmarks/servers.py S3Server)."""

import datetime as dt
import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

from benchmarks.servers import MotoS3, S3Server, nodd_key
from monitor.archive import SourceError
from monitor.archive.configured import make_source
from monitor.archive.nodd import NoddSource
from monitor.archive.ranged import BLOCK_BYTES, BLOCK_LIST
from monitor.assessment import compute_day
from monitor.config.file import load_config
from monitor.config.source import SourceConfig
from monitor.core.satellites import SATELLITES
from monitor.core.vocabulary import RunStatus
from monitor.sdr import GranuleError, read_file

pytestmark = pytest.mark.servers

DAY = dt.date(2024, 6, 1)
BUCKET = SATELLITES["j01"].bucket


@pytest.fixture(scope="module")
def moto(cases):
    out, _, _ = cases.get()
    with MotoS3() as s3:
        s3.put_granules(BUCKET, sorted(out.glob("*.h5")))
        yield s3


@pytest.fixture(scope="module")
def bucket_dir(cases, tmp_path_factory):
    """The case under NODD keys in a folder, for the hostile server."""
    out, _, _ = cases.get()
    root = tmp_path_factory.mktemp("s3")
    for f in out.glob("*.h5"):
        (root / BUCKET / nodd_key(f.name)).parent.mkdir(parents=True, exist_ok=True)
        os.link(f, root / BUCKET / nodd_key(f.name))
    return root


def _config(tmp_path, url, read, name="nodd"):
    config = tmp_path / f"{name}.yaml"
    config.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / name}\n"
        f"source: {{kind: nodd, endpoint: '{url}/{{bucket}}', retries: 1, backoff_s: 0.01, read: {read}}}\n"
        "scenes: {min_inhomogeneity_k: 0}\nfingerprint: {granules: 2}\n"
    )
    return load_config(config)


def _source(url, tmp_path, **kw):
    cfg = SourceConfig(kind="nodd", endpoint=url + "/{bucket}", retries=1, backoff_s=0.01, timeout_s=10.0)
    return NoddSource(cfg.model_copy(update=kw), tmp_path / "cache")


def test_a_day_read_in_place_is_the_whole_file_day_to_the_bit_and_its_rerun_reads_nothing(moto, tmp_path):
    whole_cfg = _config(tmp_path, moto.url, "whole", "whole")
    whole = compute_day(whole_cfg, make_source(whole_cfg), "j01", DAY)
    cfg = _config(tmp_path, moto.url, "ranges")
    first = compute_day(cfg, make_source(cfg), "j01", DAY)
    assert whole.status == first.status == RunStatus.OK, (whole.reason, first.reason)
    assert [f.to_dict() for f in first.result.fors] == [f.to_dict() for f in whole.result.fors]
    assert np.array_equal(first.result.cost_cube_k, whole.result.cost_cube_k)
    assert first.counts.downloaded == 0 and whole.counts.downloaded == whole.counts.listed
    # two CrIS granules reach every scan of the VIIRS granule: what stays home is the datasets not read
    assert first.counts.bytes < 0.85 * whole.counts.bytes  # not Radiance, QF2 or the MW, SW bands
    again = compute_day(cfg, make_source(cfg), "j01", DAY)
    assert again.status == RunStatus.OK and [f.to_dict() for f in again.result.fors] == [
        f.to_dict() for f in first.result.fors
    ]
    assert again.counts.bytes < 0.01 * first.counts.bytes


def test_blocks_are_fetched_once_and_recorded_after_a_clean_read(moto, tmp_path):
    src = _source(moto.url, tmp_path)
    f = next(x for x in src.list_day("j01", DAY, ("GITCO",)))
    ref = src.fetch(f)
    (g,) = read_file(ref, kinds=("viirs_geo",), scans=slice(10, 14))
    assert np.isfinite(g.lat_rad[10 * 32 : 14 * 32]).any() and np.isnan(g.lat_rad[: 10 * 32]).all()
    spent, requests = src.spent_bytes, src.requests
    assert 0 < spent < 0.25 * f.size  # 4 of 48 scans of three arrays, the structure, and the per-scan data
    record = json.loads((tmp_path / "cache/ranges/GITCO" / f"{f.name}{BLOCK_LIST}").read_text())
    assert record["size"] == f.size and len(record["blocks"]) == -(-spent // BLOCK_BYTES)
    (again,) = read_file(src.fetch(f), kinds=("viirs_geo",), scans=slice(10, 14))
    assert (src.spent_bytes, src.requests) == (spent, requests)  # every block from the cache
    assert np.array_equal(again.lat_rad, g.lat_rad, equal_nan=True)
    allocated = os.stat(tmp_path / "cache/ranges/GITCO" / f.name).st_blocks * 512
    assert allocated < 2 * spent  # sparse: the cache holds what was read, not the file's size


def test_the_cache_bound_evicts_files_read_in_place_by_what_they_hold(moto, tmp_path):
    src = _source(moto.url, tmp_path, cache_max_mb=0)
    f = next(x for x in src.list_day("j01", DAY, ("GITCO",)))
    read_file(src.fetch(f), kinds=("viirs_geo",), scans=slice(0, 2))
    held = tmp_path / "cache/ranges/GITCO" / f.name
    assert held.exists() and held.with_name(held.name + BLOCK_LIST).exists()
    src.start_day()
    assert not held.exists() and not held.with_name(held.name + BLOCK_LIST).exists()


def test_a_short_range_is_an_error_naming_the_key(tmp_path, bucket_dir):
    with S3Server(bucket_dir) as s3:
        src = _source(s3.url, tmp_path, retries=0)
        f = next(x for x in src.list_day("j01", DAY, ("GITCO",)))
        s3.short_ranges = True
        with pytest.raises(GranuleError) as err:
            read_file(src.fetch(f), kinds=("viirs_geo",))
    assert f.location in str(err.value) and "Content-Length" in str(err.value)
    assert not list((tmp_path / "cache").rglob(f"*{BLOCK_LIST}"))  # nothing recorded as held


def test_a_server_ignoring_the_range_is_refused_before_its_body(tmp_path, bucket_dir):
    with S3Server(bucket_dir) as s3:
        src = _source(s3.url, tmp_path, retries=0)
        f = next(x for x in src.list_day("j01", DAY, ("GITCO",)))
        s3.ignore_ranges = True
        with pytest.raises(GranuleError, match=f"{f.location} bytes 0-1048575: the server ignored the Range"):
            read_file(src.fetch(f), kinds=("viirs_geo",))
    assert src.spent_bytes == 0  # the 128 MB body was never read


def test_a_corrupt_range_is_an_error_naming_the_key_and_field(tmp_path, bucket_dir):
    """A flipped sign-and-exponent byte in a GITCO latitude of a scan read: the value stays a latitude
    (12 deg becomes -0.2 deg), so the limits pass it; the pixel-step check names it."""
    with S3Server(bucket_dir) as s3:
        src = _source(s3.url, tmp_path, retries=0)
        f = next(x for x in src.list_day("j01", DAY, ("GITCO",)))
        with h5py.File(bucket_dir / BUCKET / f.location) as h5:
            lat = h5["All_Data/VIIRS-IMG-GEO-TC_All/Latitude"]
            at = lat.id.get_offset() + (20 * 32 * 6400 + 3200) * 4 + 3  # float32 little-endian: sign+exponent
        s3.corrupt_once.add(f.location)
        s3.corrupt_at = at
        with pytest.raises(GranuleError) as err:
            read_file(src.fetch(f), kinds=("viirs_geo",), scans=slice(19, 22))
    assert (
        f.location in str(err.value)
        and "Latitude" in str(err.value)
        and "neighbouring pixels" in str(err.value)
    )


def test_a_failed_range_leaves_no_block_recorded(moto, tmp_path):
    src = _source("http://127.0.0.1:9", tmp_path, retries=0)
    f = next(x for x in _source(moto.url, tmp_path).list_day("j01", DAY, ("GCRSO",)))
    with pytest.raises(GranuleError, match=f"{f.location}.*range read"):
        read_file(src.fetch(f), kinds=("cris_geo",))
    assert not list((tmp_path / "cache").rglob(f"*{BLOCK_LIST}"))
    with pytest.raises(SourceError, match="no listed size"):
        src.fetch(type(f)(f.name, None, f.location, f.parsed)).open()


def test_reprocessing_workers_read_their_own_ranges(moto, tmp_path, monkeypatch):
    """On a Dask LocalCluster the worker process lists and reads the ranges; this process, the client,
    only records (here it cannot read at all)."""
    from monitor.service.reprocess import reprocess

    def not_here(*_):
        raise AssertionError("the client read a granule")

    monkeypatch.setattr(NoddSource, "read_range", not_here)
    monkeypatch.setattr(NoddSource, "fetch", not_here)
    cfg = _config(tmp_path, moto.url, "ranges", "reprocess")
    outcomes = []
    summary = reprocess(cfg, DAY, DAY, ["j01"], workers=1, progress=outcomes.append)
    assert summary.statuses == {"ok": 1}, [o.reason for o in outcomes]
    (out,) = outcomes
    assert out.counts.bytes > 0 and out.counts.requests > 0 and out.counts.downloaded == 0
    assert list((cfg.cache_dir / "ranges").rglob(f"*{BLOCK_LIST}"))  # the worker's block cache


_GC_IN_A_SERVICE_THREAD = """
import gc, sys, threading
from pathlib import Path
import h5py
import numpy as np
from monitor.archive import listed
from monitor.archive.ranged import RangedGranule

root = Path(sys.argv[1])
name = "GCRSO_j01_d20240601_t1200000_e1200298_b33867_c20240601123036800000_oebc_ops.h5"
with h5py.File(root / "source.h5", "w") as h5:
    h5["x"] = np.arange(1000.0)
data = (root / "source.h5").read_bytes()

class Cycle:
    pass

def collect_soon():
    gc.set_threshold(1)  # the next allocation starts a collection, here
    [[] for _ in range(100)]
    gc.set_threshold(700)

def fetch(f, start, end):
    # garbage in a cycle that holds an h5py object, and a thread the fetch waits for whose allocations
    # start a collection (as the request's watchdog does): the collection frees the h5py object
    c = Cycle()
    c.me, c.prop = c, h5py.h5p.create(h5py.h5p.FILE_ACCESS)
    del c
    worker = threading.Thread(target=collect_soon)
    worker.start()
    worker.join()
    return data[start:end]

granule = RangedGranule(listed(name, len(data), name), fetch, root / "cache")
with h5py.File(granule.open(), "r") as h5:
    print(h5["x"][-1])
"""


def test_a_collection_on_a_thread_the_fetch_waits_for_does_not_hang_the_read(tmp_path):
    """h5py holds its global lock while it reads through the file object; a garbage collection on a thread
    the fetch waits for that frees an h5py object would wait for it for ever (a known h5py bug,
    h5py/h5py#2019). Run apart, so that a hang fails the test instead of the suite."""
    done = subprocess.run(
        [sys.executable, "-c", _GC_IN_A_SERVICE_THREAD, str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "999.0"
