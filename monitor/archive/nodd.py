"""NOAA Open Data Dissemination (NODD) buckets over plain HTTPS: anonymous ListObjectsV2 and GET.

Keys are ``<product folder>/YYYY/MM/DD/<file>``, e.g. ``CrIS-SDR-GEO/2024/06/01/GCRSO_j01_...h5``
(docs/archive.md). Listings are narrowed with a file-name prefix and followed through continuation
tokens (a day holds more than the 1000 keys of one page). With ``read: ranges`` (the default) a granule
is read in place, one HTTP range request per run of missing blocks (:mod:`monitor.archive.ranged`);
with ``read: whole`` downloads go to ``<name>.part`` and are renamed only when complete, of the listed
size and, where the listing's ETag is a plain MD5, of that digest. A per-day byte budget bounds what
one run may download, and cached files older than the retention go.

Everything a server says is bounded in wall-clock time and size, so that no listing, download or range
hangs or grows without end (:mod:`monitor.archive.bounded` cuts a request at its deadline, body
included): a listing page, and the headers of any answer, come within ``timeout_s``; every request of a run
ends by the run deadline (``source.run_deadline_min``); a download or a range must keep up ``min_rate_kb_s``
over every sliding window of ``stall_window_s`` and may not bring more bytes than listed or asked for
(Content-Length is checked first); at most ``max_list_pages`` pages and ``max_listed_keys`` keys per listing,
and a continuation token seen twice is an error; Retry-After is honoured up to ``max_retry_after_s`` (a longer
one ends the attempt); a compressed response is refused (granules are stored as they are, never transparently
decoded). Redirects are followed only on the endpoint's own host. Listed keys must be plain ASCII JPSS names
in the day folder asked for (no dot segments, no field longer than the real pattern allows): a key that is
not is logged and left out, and the rest of the listing is used. There is one retry layer, here:
connection errors, 429 and 5xx, ``retries`` times with exponential backoff.
"""

from __future__ import annotations

import datetime as dt
import email.utils
import hashlib
import logging
import os
import re
import threading
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable
from pathlib import Path
from urllib.parse import urljoin, urlsplit

import requests
import urllib3

from monitor.archive import BudgetExceeded, ListedFile, SourceError, listed, ranged
from monitor.archive.bounded import BoundedSession, DeadlinePassed, StallWatch
from monitor.archive.ranged import BLOCK_LIST, RANGES_FOLDER
from monitor.config.source import SourceConfig
from monitor.core.errors import StopRequested
from monitor.core.vocabulary import ReadMode
from monitor.sdr.granules import GranuleRef
from monitor.sdr.products import CRIS_PRODUCTS, PRODUCTS

LOG = logging.getLogger(__name__)
S3_NS = "{http://s3.amazonaws.com/doc/2006-03-01/}"
MAX_LISTING_PAGE_BYTES = 8 << 20  # a page of 1000 keys is ~0.3 MB
RETRYABLE = (429, 500, 502, 503, 504)
TIMEOUTS = (TimeoutError, urllib3.exceptions.TimeoutError)  # a socket silent for the stall window
REDIRECTS = (301, 302, 303, 307, 308)
_DIGITS = re.compile(r"[0-9]{1,15}", re.ASCII)
_MD5 = re.compile(r'"?([0-9a-fA-F]{32})"?', re.ASCII)


_CONTENT_RANGE = re.compile(r"bytes ([0-9]{1,15})-([0-9]{1,15})/([0-9]{1,15})", re.ASCII)


def _retry_after_s(value: str | None) -> float | None:
    """Seconds from a Retry-After header (delta seconds or an HTTP date), None when absent or unreadable."""
    if not value:
        return None
    if _DIGITS.fullmatch(value.strip()):
        return float(value.strip())
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, (when - dt.datetime.now(dt.timezone.utc)).total_seconds()) if when.tzinfo else None


class NoddSource:
    """Granules of the NODD bucket of each satellite, cached under *cache_dir*.

    Parameters
    ----------
    cfg : SourceConfig
        The ``source`` section (bucket endpoint, bounds, budget, read mode).
    cache_dir : Path
        The download and block cache.
    sleep : callable, optional
        How a retry waits, s (``time.sleep``).
    """

    def __init__(
        self, cfg: SourceConfig, cache_dir: Path, sleep: Callable[[float], object] = time.sleep
    ) -> None:
        self.cfg = cfg
        self.cache_dir = Path(cache_dir)
        self._local = threading.local()
        self._counting = threading.Lock()
        self.spent_bytes = 0  # downloaded in this run (cache hits are free)
        self.downloaded_files = 0
        self.requests = 0  # HTTP requests sent in this run, listings included
        self.deadline: float | None = None
        self.should_stop: Callable[[], bool] = lambda: False  # the run's stop request (start_day)
        self.sleep = sleep

    @property
    def http(self) -> BoundedSession:  # numpydoc ignore=RT01
        """This thread's session. Read in place, granules are read by the assessment's read-ahead thread
        and its main thread at once, and a watchdog cuts every socket of its session: each thread's
        deadline must cut only its own requests."""
        session = getattr(self._local, "http", None)
        if session is None:
            session = self._local.http = BoundedSession()
        return session

    def _count(self, requests: int = 0, spent: int = 0, files: int = 0) -> None:
        with self._counting:
            self.requests += requests
            self.spent_bytes += spent
            self.downloaded_files += files

    def _base(self, satellite: str) -> str:
        bucket = self.cfg.buckets.get(satellite)
        if bucket is None:
            raise SourceError(f"no NODD bucket configured for {satellite}")
        return self.cfg.endpoint.format(bucket=bucket).rstrip("/")

    def start_day(self, should_stop: Callable[[], bool] | None = None) -> None:
        """Start a run: reset the day's budget and the run deadline, apply the cache retention (age, then
        size: the least recently used files go until the cache holds at most ``cache_max_mb``); the run's
        *should_stop* is polled between listing pages.

        Parameters
        ----------
        should_stop : callable, optional
            The run's stop request, polled between the long steps.
        """
        self.should_stop = should_stop or (lambda: False)
        self.spent_bytes = 0
        self.downloaded_files = 0
        self.requests = 0
        self.deadline = time.monotonic() + self.cfg.run_deadline_min * 60
        self.cache_dir.mkdir(parents=True, exist_ok=True)
        cutoff = time.time() - self.cfg.retention_days * 86400
        kept = []
        for p in self.cache_dir.rglob("*"):
            if not p.is_file() or p.suffix == BLOCK_LIST:  # a block list goes with its file
                continue
            st = p.stat()
            if p.suffix == ".part" or st.st_mtime < cutoff:
                ranged.forget(p)
            else:  # a file read in place is sparse: it takes only the blocks fetched
                kept.append((max(st.st_atime, st.st_mtime), min(st.st_size, st.st_blocks * 512), p))
        for p in self.cache_dir.rglob(f"*{BLOCK_LIST}"):
            if not p.with_suffix("").exists():
                p.unlink(missing_ok=True)
        total = sum(size for _, size, _ in kept)
        for _, size, p in sorted(kept):
            if total <= self.cfg.cache_max_mb * 1e6:
                break
            ranged.forget(p)
            total -= size

    def _run_deadline(self) -> float:
        if self.deadline is None:
            self.deadline = time.monotonic() + self.cfg.run_deadline_min * 60
        return self.deadline

    def _left_s(self, what: str) -> float:
        left = self._run_deadline() - time.monotonic()
        if left <= 0:
            raise SourceError(f"{what}: the run deadline of {self.cfg.run_deadline_min:g} min has passed")
        return left

    def _passed(self, what: str, request_deadline: float) -> SourceError:
        """The error for a request cut by the watchdog: the run deadline or the request's own bound."""
        if time.monotonic() >= self._run_deadline() or request_deadline >= self._run_deadline():
            return SourceError(f"{what}: the run deadline of {self.cfg.run_deadline_min:g} min has passed")
        return SourceError(f"{what}: no complete answer within {self.cfg.timeout_s:g} s (timeout_s)")

    def _get(
        self,
        url: str,
        what: str,
        params: dict[str, str] | None = None,
        read_timeout_s: float | None = None,
        headers: dict[str, str] | None = None,
        expect: int = 200,
    ) -> requests.Response:
        """GET *url* with the one retry layer; the response has status *expect* (200, or 206 for a range)
        with its headers read within ``timeout_s`` (and the run deadline), its body still to read (the
        caller closes it)."""
        last = "no attempt"
        for attempt in range(self.cfg.retries + 1):
            wait = self.cfg.backoff_s * 2**attempt
            left = self._left_s(what)
            bound = min(self.cfg.timeout_s, left)
            until = time.monotonic() + bound
            try:
                with self.http.guard(until):
                    self._count(requests=1)
                    r = self.http.get(
                        url,
                        params=params,
                        headers=headers,
                        stream=True,
                        timeout=(bound, read_timeout_s or bound),
                    )
            except DeadlinePassed:
                if time.monotonic() >= self._run_deadline():
                    raise self._passed(what, until) from None
                last = f"no answer within {self.cfg.timeout_s:g} s"
            except requests.RequestException as exc:
                last = type(exc).__name__
            else:
                if r.status_code == expect:
                    return r
                r.close()
                if r.status_code in REDIRECTS:
                    target = urljoin(r.url, r.headers.get("Location", ""))
                    here, there = urlsplit(r.url), urlsplit(target)
                    if (there.scheme, there.netloc) != (here.scheme, here.netloc):
                        raise SourceError(
                            f"{what}: redirect to {there.scheme}://{there.netloc} refused "
                            f"(only {here.netloc} is trusted)"
                        )
                    url, params, last = target, None, f"redirect to {there.path}"
                    continue
                if expect == 206 and r.status_code == 200:
                    raise SourceError(f"{what}: the server ignored the Range header (HTTP 200)")
                if r.status_code not in RETRYABLE:
                    raise SourceError(f"{what}: HTTP {r.status_code}")
                last = f"HTTP {r.status_code}"
                asked = _retry_after_s(r.headers.get("Retry-After"))
                if asked is not None:
                    if asked > self.cfg.max_retry_after_s:
                        raise SourceError(
                            f"{what}: HTTP {r.status_code} with Retry-After {asked:.0f} s, more than "
                            f"the {self.cfg.max_retry_after_s:g} s allowed"
                        )
                    wait = max(wait, asked)
            if attempt < self.cfg.retries:
                LOG.warning("%s: %s, retrying in %.1f s", what, last, wait)
                self.sleep(min(wait, self._left_s(what)))
        raise SourceError(f"{what}: {last} after {self.cfg.retries + 1} attempts")

    def _page(self, url: str, what: str, params: dict) -> bytes:
        """One listing page, whole within ``timeout_s`` (and the run deadline), at most
        :data:`MAX_LISTING_PAGE_BYTES`."""
        until = min(time.monotonic() + self.cfg.timeout_s, self._run_deadline())
        r = self._get(url, what, params)
        try:
            with self.http.guard(until):
                body = b""
                while len(body) <= MAX_LISTING_PAGE_BYTES:
                    chunk = r.raw.read1(MAX_LISTING_PAGE_BYTES + 1 - len(body), decode_content=True)
                    if not chunk:
                        break
                    body += chunk
        except DeadlinePassed:
            raise self._passed(what, until) from None
        except (requests.RequestException, urllib3.exceptions.HTTPError, OSError, ValueError) as exc:
            raise SourceError(f"{what}: {type(exc).__name__} while reading") from None
        finally:
            r.close()
        if len(body) > MAX_LISTING_PAGE_BYTES:
            raise SourceError(f"{what}: a page of more than {MAX_LISTING_PAGE_BYTES >> 20} MB")
        return body

    def list_prefix(self, satellite: str, prefix: str) -> list[ListedFile]:
        """Every object under *prefix* (``folder/YYYY/MM/DD/name-prefix``), following continuation tokens.

        Parameters
        ----------
        satellite : str
            The satellite's short name (its bucket).
        prefix : str
            ``folder/YYYY/MM/DD/name-prefix``.

        Returns
        -------
        list of ListedFile
            The objects.
        """
        out, token, seen = [], None, set()
        base = self._base(satellite)
        folder = prefix.rsplit("/", 1)[0] + "/"
        what = f"listing {prefix}"
        for _ in range(self.cfg.max_list_pages):
            if self.should_stop():
                raise StopRequested
            params = {"list-type": "2", "prefix": prefix, "max-keys": "1000"}
            if token:
                params["continuation-token"] = token
            body = self._page(base + "/", what, params)
            try:
                root = ET.fromstring(body)
            except ET.ParseError as exc:
                raise SourceError(f"{what}: invalid XML ({exc})") from None
            for c in root.iter(f"{S3_NS}Contents"):
                f = self._listed(c, folder, prefix)
                if f is not None:
                    out.append(f)
            if len(out) > self.cfg.max_listed_keys:
                raise SourceError(f"{what}: more than {self.cfg.max_listed_keys} keys")
            if (root.findtext(f"{S3_NS}IsTruncated") or "").strip().lower() != "true":
                return out
            token = root.findtext(f"{S3_NS}NextContinuationToken")
            if not token:
                raise SourceError(f"{what}: truncated without a continuation token")
            if token in seen:
                raise SourceError(f"{what}: the continuation token {token[:40]!r} came back")
            seen.add(token)
        raise SourceError(f"{what}: more than {self.cfg.max_list_pages} pages")

    @staticmethod
    def _listed(c: ET.Element, folder: str, prefix: str) -> ListedFile | None:
        key = c.findtext(f"{S3_NS}Key") or ""
        size = (c.findtext(f"{S3_NS}Size") or "").strip()
        etag = _MD5.fullmatch((c.findtext(f"{S3_NS}ETag") or "").strip())
        name = key[len(folder) :]
        ok = key.isascii() and key.startswith(prefix) and "/" not in name and _DIGITS.fullmatch(size)
        f = listed(name, int(size), key, etag.group(1).lower() if etag else None) if ok else None
        if f is None:
            LOG.warning(
                "ignoring listed key %r (size %r): not a plain JPSS granule name under %s",
                key[:200],
                size[:20],
                folder,
            )
        return f

    def list_day(self, satellite: str, day: dt.date, products: Iterable[str]) -> list[ListedFile]:
        """The day's files of *products* in the satellite's bucket (the newest creation per granule).

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        products : iterable of str
            The product prefixes wanted (GCRSO, SCRIF, SVI05, GITCO, ...).

        Returns
        -------
        list of ListedFile
            The files.
        """
        out = []
        for product in products:
            folder = PRODUCTS[product].collection  # the NODD folder is the collection name
            prefixes = [(day, f"{product}_{satellite}_d{day:%Y%m%d}")]
            if (
                product not in CRIS_PRODUCTS
            ):  # VIIRS granules spanning midnight cover the day's first/last CrIS
                prev, nxt = day - dt.timedelta(days=1), day + dt.timedelta(days=1)
                prefixes += [
                    (prev, f"{product}_{satellite}_d{prev:%Y%m%d}_t23"),
                    (nxt, f"{product}_{satellite}_d{nxt:%Y%m%d}_t00"),
                ]
            for d, name_prefix in prefixes:
                out += self.list_prefix(satellite, f"{folder}/{d:%Y/%m/%d}/{name_prefix}")
        return _newest_per_granule(out)

    def fetch(self, f: ListedFile) -> GranuleRef:
        """*f* to read: with ``read: ranges`` a granule read in place through the block cache (nothing is
        fetched yet); with ``read: whole`` the cached copy, downloaded (bounded, checked against the
        listing) if missing.

        Parameters
        ----------
        f : ListedFile
            A listed file.

        Returns
        -------
        GranuleRef
            A granule read in place, or the cached file's path.
        """
        if self.cfg.read == ReadMode.RANGES:
            return ranged.RangedGranule(f, self.read_range, self.cache_dir / RANGES_FOLDER)
        folder = self.cache_dir / f.product
        target = folder / f.name  # f.name is a checked base name: it cannot leave the cache
        try:
            folder.mkdir(parents=True, exist_ok=True)
            if target.exists() and (f.size is None or target.stat().st_size == f.size):
                os.utime(target)  # used now: the size bound evicts the least recently used first
                return target
        except OSError as exc:
            raise SourceError(f"{f.name}: cache {folder}: {exc.strerror or exc}") from None
        if f.size is not None and self.spent_bytes + f.size > self.cfg.daily_budget_mb * 1e6:
            raise BudgetExceeded(
                f"{f.name}: the day's download budget of {self.cfg.daily_budget_mb:.0f} MB is spent"
            )
        part = target.with_name(target.name + ".part")
        url = f"{self._base(f.parsed.platform)}/{f.location}"
        last = None
        for attempt in range(self.cfg.retries + 1):
            try:
                n = self._download(url, f, part)
                os.replace(part, target)
            except SourceError as exc:
                last = exc
                part.unlink(missing_ok=True)
                if attempt < self.cfg.retries and "refused" not in str(exc) and "deadline" not in str(exc):
                    LOG.warning("download of %s failed (attempt %d): %s", f.name, attempt + 1, exc)
                    self.sleep(min(self.cfg.backoff_s * 2**attempt, self._left_s(f.name)))
                    continue
                break
            except OSError as exc:  # the cache cannot hold it (disk full, a name too long): not retried
                part.unlink(missing_ok=True)
                raise SourceError(f"{f.name}: cannot write to the cache ({exc.strerror or exc})") from None
            self._count(spent=n, files=1)
            return target
        raise SourceError(f"{f.name}: download failed ({last})")

    def _download(self, url: str, f: ListedFile, part: Path) -> int:
        """One download into *part*: bounded in bytes, stalls and the run deadline, checked against the
        listing."""
        window = min(self.cfg.stall_window_s, self.cfg.timeout_s)
        r = self._get(url, f.name, read_timeout_s=window)
        try:
            encoding = r.headers.get("Content-Encoding", "identity").strip().lower()
            if encoding not in ("", "identity"):
                raise SourceError(f"{f.name}: compressed response (Content-Encoding {encoding[:20]}) refused")
            length = r.headers.get("Content-Length")
            if f.size is not None and length is not None and length.strip() != str(f.size):
                raise SourceError(f"{f.name}: Content-Length {length[:20]}, the listing says {f.size}")
            md5 = hashlib.md5() if f.md5 else None
            with open(part, "wb") as out:
                watch = self._body(r, f.name, f.size, out.write, md5)
                out.flush()
                os.fsync(out.fileno())
        finally:
            r.close()
        n = watch.total
        if f.size is not None and n != f.size:
            raise SourceError(f"{f.name}: got {n} bytes, the listing says {f.size}")
        if md5 is not None and md5.hexdigest() != f.md5:
            raise SourceError(f"{f.name}: MD5 {md5.hexdigest()} differs from the listing's ETag {f.md5}")
        return n

    def _body(
        self,
        r: requests.Response,
        what: str,
        limit: int | None,
        sink: Callable[[bytes], object],
        md5: hashlib._Hash | None = None,
    ) -> StallWatch:
        """Read the body of *r* into *sink*, at most *limit* bytes, cut by a stall (``min_rate_kb_s`` over
        ``stall_window_s``) and by the run deadline; returns the transfer's watch (its total)."""
        watch = StallWatch(self.cfg.min_rate_kb_s * 1e3, self.cfg.stall_window_s)
        try:
            with self.http.guard(self._run_deadline()):
                while True:
                    try:
                        chunk = r.raw.read1(1 << 20, decode_content=False)
                    except (
                        requests.RequestException,
                        urllib3.exceptions.HTTPError,
                        OSError,
                        ValueError,
                    ) as exc:
                        if watch.stalled() or isinstance(exc, TIMEOUTS):
                            raise self._stalled(what, watch) from None
                        raise SourceError(f"{what}: {type(exc).__name__} after {watch.total} B") from None
                    if not chunk:
                        return watch
                    watch.add(len(chunk))
                    if limit is not None and watch.total > limit:
                        raise SourceError(f"{what}: more than the {limit} bytes asked for or listed")
                    if watch.stalled():
                        raise self._stalled(what, watch)
                    sink(chunk)
                    if md5 is not None:
                        md5.update(chunk)
        except DeadlinePassed:
            raise SourceError(
                f"{what}: the run deadline of {self.cfg.run_deadline_min:g} min has passed"
            ) from None

    def read_range(self, f: ListedFile, start: int, end: int) -> bytes:
        """Bytes *start* to *end* (exclusive) of *f*, in one HTTP range request under every bound of a
        download (the one retry layer, ``timeout_s`` for the headers, the stall window, the run deadline,
        the day's budget, redirects only on the endpoint's host): exactly those bytes of an object of the
        listed size, or a :class:`SourceError` naming the key and the range.

        Parameters
        ----------
        f : ListedFile
            A listed file.
        start, end : int
            The byte range, end exclusive.

        Returns
        -------
        bytes
            Exactly those bytes.
        """
        what = f"{f.location} bytes {start}-{end - 1}"
        if self.spent_bytes + (end - start) > self.cfg.daily_budget_mb * 1e6:
            raise BudgetExceeded(
                f"{what}: the day's download budget of {self.cfg.daily_budget_mb:.0f} MB is spent"
            )
        url = f"{self._base(f.parsed.platform)}/{f.location}"
        last = None
        for attempt in range(self.cfg.retries + 1):
            try:
                data = self._range(url, what, f, start, end)
            except SourceError as exc:
                last = exc
                if attempt < self.cfg.retries and "refused" not in str(exc) and "deadline" not in str(exc):
                    LOG.warning("range read failed (attempt %d): %s", attempt + 1, exc)
                    self.sleep(min(self.cfg.backoff_s * 2**attempt, self._left_s(what)))
                    continue
                break
            self._count(spent=len(data))
            return data
        raise SourceError(f"{what}: range read failed ({last})")

    def _range(self, url: str, what: str, f: ListedFile, start: int, end: int) -> bytes:
        """One range request: status 206, Content-Range and Content-Length exactly the range asked for,
        of an object of the listed size, never content-encoded."""
        window = min(self.cfg.stall_window_s, self.cfg.timeout_s)
        r = self._get(
            url, what, read_timeout_s=window, headers={"Range": f"bytes={start}-{end - 1}"}, expect=206
        )
        try:
            encoding = r.headers.get("Content-Encoding", "identity").strip().lower()
            if encoding not in ("", "identity"):
                raise SourceError(f"{what}: compressed response (Content-Encoding {encoding[:20]}) refused")
            span = _CONTENT_RANGE.fullmatch(r.headers.get("Content-Range", "").strip())
            if span is None or (int(span[1]), int(span[2]) + 1) != (start, end):
                raise SourceError(f"{what}: Content-Range {r.headers.get('Content-Range', '')[:60]!r}")
            if f.size is not None and int(span[3]) != f.size:
                raise SourceError(f"{what}: the object holds {span[3]} bytes, the listing says {f.size}")
            length = r.headers.get("Content-Length")
            if length is not None and length.strip() != str(end - start):
                raise SourceError(f"{what}: Content-Length {length[:20]} for {end - start} bytes")
            body = bytearray()
            self._body(r, what, end - start, body.extend)
        finally:
            r.close()
        if len(body) != end - start:
            raise SourceError(f"{what}: got {len(body)} bytes of {end - start}")
        return bytes(body)

    def _stalled(self, what: str, watch: StallWatch) -> SourceError:
        return SourceError(
            f"{what}: slower than {self.cfg.min_rate_kb_s:g} kB/s over {self.cfg.stall_window_s:g} s "
            f"({watch.total} bytes received)"
        )


def _newest_per_granule(files: list[ListedFile]) -> list[ListedFile]:
    """Reprocessed granules reappear with a newer creation time: keep the newest of each."""
    best: dict[tuple[str, str], ListedFile] = {}
    for f in files:
        key = (f.product, f.parsed.granule_key)
        if key not in best or best[key].parsed.created < f.parsed.created:
            best[key] = f
    return sorted(best.values(), key=lambda f: (f.parsed.start, f.product))
