"""The NODD source against a real HTTP server on loopback that speaks S3 ListObjectsV2."""

import datetime as dt
import os
import shutil
import time
from pathlib import Path

import pytest

from benchmarks.servers import S3Server, nodd_key
from monitor.archive import ALL_PRODUCTS, BudgetExceeded, SourceError, listed
from monitor.archive.configured import make_source
from monitor.archive.nodd import NoddSource
from monitor.assessment import compute_day
from monitor.config.file import load_config
from monitor.config.source import SourceConfig
from monitor.core.vocabulary import RunStatus

DAY = dt.date(2024, 6, 1)


@pytest.fixture(scope="module")
def bucket(cases, tmp_path_factory):
    out, _, _ = cases.get()
    root = tmp_path_factory.mktemp("s3")
    for f in out.glob("*.h5"):
        (root / "noaa-nesdis-n20-pds" / nodd_key(f.name)).parent.mkdir(parents=True, exist_ok=True)
        # the server serves only files inside its root (no symlinks out)
        os.link(f, root / "noaa-nesdis-n20-pds" / nodd_key(f.name))
    # more keys than one listing page, and a reprocessed copy of a granule with a newer creation time
    d = root / "noaa-nesdis-n20-pds" / "CrIS-SDR-GEO/2024/06/01"
    first = sorted(d.glob("GCRSO_*.h5"))[0]
    shutil.copy(first, d / first.name.replace("_c2024", "_c2025"))
    return root


MODES = ("whole", "ranges")  # every download bound holds for a whole file and for a range alike


def _source(url, tmp_path, **kw):
    """A NODD source on the test server; *kw* may narrow bounds below what a file may set (a budget of
    0.1 MB, a deadline of 3 s: the tests run in seconds), so they are applied after validation."""
    cfg = SourceConfig(kind="nodd", endpoint=url + "/{bucket}", retries=2, backoff_s=0.01, timeout_s=10.0)
    return NoddSource(cfg.model_copy(update=kw), tmp_path / "cache")


def _read(src, f) -> bytes:
    """The bytes of *f* as the source gives them: the file downloaded whole, or every byte read in place
    (a failed read raises the transport's error, as the readers report it)."""
    ref = src.fetch(f)
    if isinstance(ref, Path):
        return ref.read_bytes()
    with ref.open() as fh:
        try:
            return fh.read()
        except OSError:
            raise SourceError(fh.failure) from None


def _nothing_held(cache: Path) -> bool:
    """No partial download and no block recorded as held."""
    return not list(cache.rglob("*.part")) + list(cache.rglob("*.blocks")) + list(cache.glob("[!r]*/*.h5"))


@pytest.mark.servers
def test_listing_follows_pages_and_keeps_newest(bucket, tmp_path):
    with S3Server(bucket, page_size=2) as s3:
        src = _source(s3.url, tmp_path)
        files = src.list_day("j01", DAY, ALL_PRODUCTS)
        assert sum(1 for r in s3.requests if "continuation-token" in r) >= 1
    names = [f.name for f in files]
    assert sum(n.startswith("GCRSO") for n in names) == 2 and sum(n.startswith("SCRIF") for n in names) == 2
    assert sum(n.startswith("SVI05") for n in names) == 1 and sum(n.startswith("GITCO") for n in names) == 1
    assert any("_c2025" in n for n in names)  # the reprocessed granule replaces the original


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_dropped_connection_is_retried_and_never_leaves_a_partial_granule(bucket, tmp_path, read):
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, read=read)
        f = [x for x in src.list_day("j01", DAY, ("GCRSO",))][1]
        s3.drop_once.add(f.location)
        assert _read(src, f) == (bucket / "noaa-nesdis-n20-pds" / f.location).read_bytes()
        assert not list((tmp_path / "cache").rglob("*.part"))
        assert sum(f.name in r for r in s3.requests) == 2  # the cut download, then the full one


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_size_mismatch_and_budget(bucket, tmp_path, read):
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, daily_budget_mb=0.1, read=read)
        f = src.list_day("j01", DAY, ("GCRSO",))[1]
        wrong = type(f)(f.name, f.size + 1, f.location, f.parsed)
        with pytest.raises(SourceError, match="listing says" if read == "whole" else "Content-Range"):
            _read(src, wrong)
        assert _nothing_held(tmp_path / "cache")
        src.start_day()
        big = src.list_day("j01", DAY, ("SCRIF",))[0]
        with pytest.raises(BudgetExceeded if read == "whole" else SourceError, match="budget"):
            _read(src, big)


@pytest.mark.servers
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


# -- a hostile server: every fault ends within its bound, with a reason, and nothing grows without end


def _timed(fn):
    import tracemalloc

    tracemalloc.start()
    t0 = time.monotonic()
    try:
        fn()
    except SourceError as exc:
        return time.monotonic() - t0, tracemalloc.get_traced_memory()[1], str(exc)
    finally:
        tracemalloc.stop()
    pytest.fail("no SourceError")


@pytest.mark.servers
def test_endless_and_repeated_continuation_tokens_end(bucket, tmp_path):
    with S3Server(bucket, page_size=1) as s3:
        s3.endless_tokens = True
        secs, peak, why = _timed(
            lambda: _source(s3.url, tmp_path, max_list_pages=20).list_day("j01", DAY, ("GCRSO",))
        )
        assert "more than 20 pages" in why and secs < 10 and peak < 20e6
        assert sum("continuation-token" in r for r in s3.requests) == 19
    with S3Server(bucket, page_size=1) as s3:
        s3.repeat_token = True
        secs, _, why = _timed(lambda: _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",)))
        assert "continuation token 'c2FtZQ==' came back" in why and len(s3.requests) == 2


@pytest.mark.servers
def test_a_huge_retry_after_is_not_waited_for(bucket, tmp_path):
    with S3Server(bucket) as s3:
        s3.retry_after = 3600
        secs, _, why = _timed(lambda: _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",)))
        assert "Retry-After 3600 s, more than the 120 s allowed" in why and secs < 5 and len(s3.requests) == 1


@pytest.mark.parametrize(
    "bound,reason,limit_s",
    [
        ({"min_rate_kb_s": 1000.0, "stall_window_s": 2.0}, "slower than 1000 kB/s over 2 s", 2 + 10),
        ({"run_deadline_min": 0.05}, "run deadline of 0.05 min has passed", 3 + 10),
    ],
)
@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_a_slow_drip_download_is_cut(bucket, tmp_path, bound, reason, limit_s, read):
    """By the minimum rate over the stall window, or by the run deadline, whichever comes first: each
    within its bound + 10 s."""
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, retries=0, read=read, **bound)
        f = src.list_day("j01", DAY, ("SCRIF",))[0]
        s3.slow_drip_s = 0.05
        secs, peak, why = _timed(lambda: _read(src, f))
        assert reason in why and secs < limit_s and peak < 20e6
        assert _nothing_held(tmp_path / "cache")  # no partial granule left


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_one_byte_a_second_is_a_stall_not_a_budget(bucket, tmp_path, read):
    """A drip of one byte at a time is cut after one stall window (before: a budget of 30 s + size / rate,
    ~2600 s for a GITCO); retried, each attempt is cut the same way."""
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, retries=1, stall_window_s=2.0, min_rate_kb_s=1.0, read=read)
        f = src.list_day("j01", DAY, ("SCRIF",))[0]
        s3.slow_drip_s, s3.drip_bytes = 0.02, 1
        secs, _, why = _timed(lambda: _read(src, f))
        assert "slower than 1 kB/s over 2 s" in why and secs < 2 * 2 + 10
        assert sum(f.name in r for r in s3.requests) == 2


@pytest.mark.servers
def test_a_slow_listing_ends_within_the_request_bound(bucket, tmp_path):
    """A listing page sent at one byte per 0.2 s (~90 s for the page) is cut at timeout_s, body included;
    before, only each read had a timeout and the page took as long as the server liked."""
    with S3Server(bucket) as s3:
        s3.slow_list_s = 0.2
        secs, _, why = _timed(lambda: _source(s3.url, tmp_path, timeout_s=3).list_day("j01", DAY, ("GCRSO",)))
        assert "no complete answer within 3 s" in why and secs < 3 + 10
        assert len(s3.requests) == 1


@pytest.mark.servers
def test_slow_headers_end_within_the_request_bound(bucket, tmp_path):
    """Headers trickled one byte at a time are cut at timeout_s, and the retries are bounded the same."""
    with S3Server(bucket) as s3:
        s3.slow_headers_s = 0.2
        secs, _, why = _timed(
            lambda: _source(s3.url, tmp_path, timeout_s=2, retries=1).list_day("j01", DAY, ("GCRSO",))
        )
        assert "no answer within 2 s after 2 attempts" in why and secs < 2 * 2 + 10


@pytest.mark.servers
def test_the_run_deadline_cuts_a_listing_in_flight(bucket, tmp_path):
    with S3Server(bucket) as s3:
        s3.slow_list_s = 0.2
        src = _source(s3.url, tmp_path, timeout_s=60, run_deadline_min=0.05)
        src.start_day()
        secs, _, why = _timed(lambda: src.list_day("j01", DAY, ("GCRSO",)))
        assert "run deadline of 0.05 min has passed" in why and secs < 3 + 10


@pytest.mark.servers
def test_a_name_longer_than_the_pattern_is_left_out_and_the_day_goes_on(bucket, tmp_path):
    """A listed name with a 300-digit orbit number: before, it passed the name check, its cache write
    failed with 'File name too long' and the whole day was recorded failed."""
    folder = "CrIS-SDR-GEO/2024/06/01/"
    with S3Server(bucket) as s3:
        genuine = _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",))
        g = genuine[0].name
        b = g.split("_b", 1)[1].split("_", 1)[0]
        long_orbit = g.replace(f"_b{b}_", f"_b{'7' * 300}_")
        s3.extra_keys = [folder + long_orbit, folder + g.replace("GCRSO", "GCRSO" * 40, 1)]
        files = _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",))
    assert sorted(f.name for f in files) == sorted(f.name for f in genuine)


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_a_cache_that_cannot_hold_a_file_is_a_source_error(bucket, tmp_path, read):
    """An OSError of the cache (here: a file where the product folder should be) names the file; it is not
    retried and does not escape as an OSError (which failed the whole day)."""
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, read=read)
        f = src.list_day("j01", DAY, ("GCRSO",))[0]
        folder = tmp_path / "cache" / ("GCRSO" if read == "whole" else "ranges/GCRSO")
        folder.parent.mkdir(parents=True)
        folder.write_text("not a folder")
        with pytest.raises(
            SourceError, match=f"{f.name}: cache" if read == "whole" else f"{f.location}: block cache"
        ):
            _read(src, f)


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_a_lying_size_and_a_gzip_response_are_refused(bucket, tmp_path, read):
    with S3Server(bucket) as s3:
        s3.lying_size = 1000
        src = _source(s3.url, tmp_path, read=read)
        f = src.list_day("j01", DAY, ("SCRIF",))[0]
        secs, peak, why = _timed(lambda: _read(src, f))
        assert "listing says 1000" in why and peak < 20e6  # the server's copy too
        assert ("Content-Length" if read == "whole" else "the object holds 1000000000 bytes") in why
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, read=read)
        f = src.list_day("j01", DAY, ("GCRSO",))[0]
        s3.gzip = True
        secs, _, why = _timed(lambda: _read(src, f))
        assert "compressed response (Content-Encoding gzip) refused" in why
    assert _nothing_held(tmp_path / "cache")


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_md5_against_the_etag(bucket, tmp_path, read):
    """Read in place, a granule of one block (the GCRSO) is checked whole before any byte is used."""
    with S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, retries=0, read=read)
        f = src.list_day("j01", DAY, ("GCRSO",))[0]
        assert f.md5 is not None and len(f.md5) == 32
        s3.corrupt_once.add(f.location)
        secs, _, why = _timed(lambda: _read(src, f))
        assert "MD5" in why and "differs from the listing's ETag" in why
        assert _read(src, f) == (bucket / "noaa-nesdis-n20-pds" / f.location).read_bytes()


@pytest.mark.servers
def test_odd_keys_never_shadow_the_granule(bucket, tmp_path):
    folder = "CrIS-SDR-GEO/2024/06/01/"
    with S3Server(bucket) as s3:
        genuine = _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",))
        g = next(f.name for f in genuine if "_c2024" in f.name)
        newer = g.replace("_c2024", "_c2099")
        s3.extra_keys = [
            folder + "./" + newer,
            folder + "sub/../" + newer,
            folder + newer.replace("_t12", "_t\u0661\u0662"),
            folder + g.replace("_t1200", "_t1299").replace("_e1200", "_e1299"),
            folder + newer.replace("_c2099", "_c2098"),
        ]
        s3.extra_sizes = {folder + newer.replace("_c2099", "_c2098"): "\u00b2"}
        files = _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",))
    assert sorted(f.name for f in files) == sorted(f.name for f in genuine)


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_a_redirect_to_another_host_is_refused(bucket, tmp_path, read):
    with S3Server(bucket, host="127.0.0.2") as other, S3Server(bucket) as s3:
        src = _source(s3.url, tmp_path, read=read)
        f = src.list_day("j01", DAY, ("GCRSO",))[0]
        s3.redirect_to = other.url
        secs, _, why = _timed(lambda: _read(src, f))
        assert "redirect to http://127.0.0.2" in why and "refused" in why
        assert other.requests == []
        s3.redirect_to = s3.url  # on the same host a redirect is followed
        assert len(_read(src, f)) == f.size


@pytest.mark.servers
def test_one_retry_layer(bucket, tmp_path):
    """503s are retried `retries` times by the source alone (no urllib3 Retry nested inside: that made up
    to 36 attempts per file)."""
    with S3Server(bucket) as s3:
        s3.retry_after = 0
        secs, _, why = _timed(lambda: _source(s3.url, tmp_path, retries=3).list_day("j01", DAY, ("GCRSO",)))
        assert "HTTP 503 after 4 attempts" in why and len(s3.requests) == 4


@pytest.mark.servers
@pytest.mark.parametrize("read", MODES)
def test_a_day_with_hostile_keys_is_assessed_from_the_good_granules(bucket, tmp_path, read):
    """End to end: the listing also holds a name with a 300-digit orbit and a name that leaves the folder;
    the day is still assessed from its genuine granules, and recorded ok."""
    folder = "CrIS-SDR-GEO/2024/06/01/"
    with S3Server(bucket) as s3:
        good = _source(s3.url, tmp_path).list_day("j01", DAY, ("GCRSO",))[0].name
        b = good.split("_b", 1)[1].split("_", 1)[0]
        s3.extra_keys = [folder + good.replace(f"_b{b}_", f"_b{'7' * 300}_"), folder + "../../x/" + good]
        config = tmp_path / "nodd.yaml"
        config.write_text(
            f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
            f"source: {{kind: nodd, endpoint: '{s3.url}/{{bucket}}', retries: 1, backoff_s: 0.01, "
            f"read: {read}}}\n"
            "scenes: {min_inhomogeneity_k: 0}\nfingerprint: {granules: 2}\n"
        )
        cfg = load_config(config)
        work = compute_day(cfg, make_source(cfg), "j01", DAY)
    assert work.status == RunStatus.OK, work.reason
    assert work.counts.assessed == 2 and len(work.result.fors) == 30


@pytest.mark.servers
def test_a_stop_requested_during_listing_ends_it_within_a_page(bucket, tmp_path):
    """SIGTERM while the day's listings page through the archive: the next page is not asked for."""
    from monitor.core.errors import StopRequested

    with S3Server(bucket, page_size=1) as s3:
        src = _source(s3.url, tmp_path)
        src.start_day(lambda: len(s3.requests) >= 2)  # the stop comes after two pages
        with pytest.raises(StopRequested):
            src.list_day("j01", DAY, ("GCRSO",))
        assert len(s3.requests) == 2  # a listing of one-key pages would have asked for more
