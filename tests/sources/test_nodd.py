"""The NODD source against a real HTTP server on loopback that speaks S3 ListObjectsV2."""

import datetime as dt
import os
import shutil
import time

import pytest

from monitor.config import SourceConfig
from monitor.sources import ALL_PRODUCTS, BudgetExceeded, SourceError, listed
from monitor.sources.nodd import NoddSource
from tests.servers import S3Server

DAY = dt.date(2024, 6, 1)
FOLDER = {"GCRSO": "CrIS-SDR-GEO", "SCRIF": "CrIS-FS-SDR", "SVI05": "VIIRS-I5-SDR", "GITCO": "VIIRS-IMG-GEO-TC"}


@pytest.fixture(scope="module")
def bucket(cases, tmp_path_factory):
    out, _, _ = cases.get()
    root = tmp_path_factory.mktemp("s3")
    for f in out.glob("*.h5"):
        product = f.name.split("_")[0]
        d = root / "noaa-nesdis-n20-pds" / FOLDER[product] / "2024/06/01"
        d.mkdir(parents=True, exist_ok=True)
        if product in ("GCRSO", "SCRIF"):
            shutil.copy(f, d / f.name)
        else:
            (d / f.name).symlink_to(f)
    # more keys than one listing page, and a reprocessed copy of a granule with a newer creation time
    d = root / "noaa-nesdis-n20-pds" / "CrIS-SDR-GEO/2024/06/01"
    first = sorted(d.glob("GCRSO_*.h5"))[0]
    shutil.copy(first, d / first.name.replace("_c2024", "_c2025"))
    return root


def _source(url, tmp_path, **kw):
    cfg = SourceConfig(kind="nodd", endpoint=url + "/{bucket}", retries=2, backoff_s=0.01, timeout_s=10, **kw)
    return NoddSource(cfg, tmp_path / "cache")


def test_listing_follows_pages_and_keeps_newest(bucket, tmp_path):
    with S3Server(bucket, page_size=2) as s3:
        src = _source(s3.url, tmp_path)
        files = src.list_day("j01", DAY, ALL_PRODUCTS)
        assert sum(1 for r in s3.requests if "continuation-token" in r) >= 1
    names = [f.name for f in files]
    assert sum(n.startswith("GCRSO") for n in names) == 2 and sum(n.startswith("SCRIF") for n in names) == 2
    assert sum(n.startswith("SVI05") for n in names) == 1 and sum(n.startswith("GITCO") for n in names) == 1
    assert any("_c2025" in n for n in names)  # the reprocessed granule replaces the original


def test_dropped_connection_is_retried_and_never_leaves_a_partial_granule(bucket, tmp_path):
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path)
        f = [x for x in src.list_day("j01", DAY, ("GCRSO",))][1]
        s3.drop_once.add(f.location)
        path = src.fetch(f)
        assert path.read_bytes() == (bucket / "noaa-nesdis-n20-pds" / f.location).read_bytes()
        assert not list((tmp_path / "cache").rglob("*.part"))
        assert sum(f.name in r for r in s3.requests) == 2  # the cut download, then the full one


def test_size_mismatch_and_budget(bucket, tmp_path):
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, daily_budget_mb=0.1)
        f = src.list_day("j01", DAY, ("GCRSO",))[1]
        wrong = type(f)(f.name, f.size + 1, f.location, f.parsed)
        with pytest.raises(SourceError, match="listing says"):
            src.fetch(wrong)
        assert not (tmp_path / "cache" / "GCRSO" / f.name).exists()
        src.start_day()
        big = src.list_day("j01", DAY, ("SCRIF",))[0]
        with pytest.raises(BudgetExceeded, match="budget"):
            src.fetch(big)


def test_unsafe_keys_are_ignored(bucket, tmp_path):
    assert listed("../../etc/passwd", 1, "x") is None and listed(".hidden.h5", 1, "x") is None
    with S3Server(bucket) as s3:
        s3.extra_keys = ["CrIS-SDR-GEO/2024/06/01/GCRSO_j01_d20240601/../../../../evil.h5"]
        src = _source(s3.url, tmp_path)
        files = src.list_day("j01", DAY, ("GCRSO",))
    assert all("evil" not in f.name for f in files)


def test_retention_removes_old_cache_files(tmp_path):
    src = _source("http://127.0.0.1:9", tmp_path, retention_days=7)
    old = tmp_path / "cache" / "GCRSO" / "old.h5"
    old.parent.mkdir(parents=True)
    old.write_bytes(b"x")
    os.utime(old, (time.time() - 9 * 86400,) * 2)
    new = old.with_name("new.h5")
    new.write_bytes(b"y")
    src.start_day()
    assert not old.exists() and new.exists()


def test_unreachable_server_is_a_source_error(tmp_path):
    src = _source("http://127.0.0.1:9", tmp_path)
    with pytest.raises(SourceError, match="listing"):
        src.list_day("j01", DAY, ("GCRSO",))
