"""NOAA Open Data Dissemination (NODD) buckets over plain HTTPS: anonymous ListObjectsV2 and GET.

Keys are ``<product folder>/YYYY/MM/DD/<file>``, e.g. ``CrIS-SDR-GEO/2024/06/01/GCRSO_j01_...h5``
(docs/archive.md). Listings are narrowed with a file-name prefix and followed through continuation
tokens (a day holds more than the 1000 keys of one page). Downloads go to ``<name>.part`` and are
renamed only when complete, of the listed size and, where the listing's ETag is a plain MD5, of that
digest. A per-day byte budget bounds what one run may download, and cached files older than the
retention go.

Everything a server says is bounded, so that no listing or download hangs or grows without end: a run
deadline (``source.run_deadline_min``) for all requests of a run; at most ``max_list_pages`` pages and
``max_listed_keys`` keys per listing, and a continuation token seen twice is an error; Retry-After is
honoured up to ``max_retry_after_s`` (a longer one ends the attempt); a download must keep up
``min_rate_kb_s`` and may not bring more bytes than listed (Content-Length is checked first); a
compressed response is refused (granules are stored as they are, never transparently decoded).
Redirects are followed only on the endpoint's own host. Listed keys must be plain ASCII JPSS names in
the day folder asked for (no dot segments). There is one retry layer, here: connection errors, 429
and 5xx, ``retries`` times with exponential backoff.
"""

from __future__ import annotations

import datetime as dt
import email.utils
import hashlib
import logging
import os
import re
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from urllib.parse import urljoin, urlsplit

import requests
import urllib3

from monitor.sdr.products import CRIS_PRODUCTS, PRODUCTS
from monitor.sources import BudgetExceeded, ListedFile, SourceError, listed

LOG = logging.getLogger(__name__)
S3_NS = "{http://s3.amazonaws.com/doc/2006-03-01/}"
MAX_LISTING_PAGE_BYTES = 8 << 20  # a page of 1000 keys is ~0.3 MB
RETRYABLE = (429, 500, 502, 503, 504)
REDIRECTS = (301, 302, 303, 307, 308)
_DIGITS = re.compile(r"[0-9]{1,15}", re.ASCII)
_MD5 = re.compile(r'"?([0-9a-fA-F]{32})"?', re.ASCII)


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
    """Granules of the NODD bucket of each satellite, cached under *cache_dir*."""

    def __init__(self, cfg, cache_dir: Path, sleep=time.sleep):
        self.cfg = cfg
        self.cache_dir = Path(cache_dir)
        self.session = requests.Session()  # no urllib3 Retry: the one retry layer is _get
        self.session.headers["Accept-Encoding"] = "identity"
        self.spent_bytes = 0  # downloaded in this run (cache hits are free)
        self.downloaded_files = 0
        self.deadline = None
        self.sleep = sleep

    def _base(self, satellite: str) -> str:
        bucket = self.cfg.buckets.get(satellite)
        if bucket is None:
            raise SourceError(f"no NODD bucket configured for {satellite}")
        return self.cfg.endpoint.format(bucket=bucket).rstrip("/")

    def start_day(self):
        """Start a run: reset the day's budget and the run deadline, apply the cache retention."""
        self.spent_bytes = 0
        self.downloaded_files = 0
        self.deadline = time.monotonic() + self.cfg.run_deadline_min * 60
        self.cache_dir.mkdir(parents=True, exist_ok=True)
        cutoff = time.time() - self.cfg.retention_days * 86400
        for p in self.cache_dir.rglob("*"):
            if p.is_file() and (p.suffix == ".part" or p.stat().st_mtime < cutoff):
                p.unlink(missing_ok=True)

    def _left_s(self, what: str) -> float:
        if self.deadline is None:
            self.deadline = time.monotonic() + self.cfg.run_deadline_min * 60
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise SourceError(f"{what}: the run deadline of {self.cfg.run_deadline_min:g} min has passed")
        return left

    def _get(self, url: str, what: str, params=None, stream=False) -> requests.Response:
        """GET *url* with the one retry layer; the response is 200 (the caller closes it)."""
        last = "no attempt"
        for attempt in range(self.cfg.retries + 1):
            wait = self.cfg.backoff_s * 2**attempt
            try:
                r = self.session.get(
                    url,
                    params=params,
                    stream=stream,
                    allow_redirects=False,
                    timeout=min(self.cfg.timeout_s, self._left_s(what)),
                )
            except requests.RequestException as exc:
                last = type(exc).__name__
            else:
                if r.status_code == 200:
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

    def list_prefix(self, satellite: str, prefix: str) -> list[ListedFile]:
        """Every object under *prefix* (``folder/YYYY/MM/DD/name-prefix``), following continuation tokens."""
        out, token, seen = [], None, set()
        base = self._base(satellite)
        folder = prefix.rsplit("/", 1)[0] + "/"
        what = f"listing {prefix}"
        for _ in range(self.cfg.max_list_pages):
            params = {"list-type": "2", "prefix": prefix, "max-keys": "1000"}
            if token:
                params["continuation-token"] = token
            r = self._get(base + "/", what, params, stream=True)
            try:
                body = r.raw.read(MAX_LISTING_PAGE_BYTES + 1, decode_content=True)
            except (requests.RequestException, urllib3.exceptions.HTTPError, OSError, ValueError) as exc:
                raise SourceError(f"{what}: {type(exc).__name__} while reading") from None
            finally:
                r.close()
            if len(body) > MAX_LISTING_PAGE_BYTES:
                raise SourceError(f"{what}: a page of more than {MAX_LISTING_PAGE_BYTES >> 20} MB")
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
    def _listed(c, folder: str, prefix: str) -> ListedFile | None:
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

    def list_day(self, satellite: str, day: dt.date, products) -> list[ListedFile]:
        """The day's files of *products* in the satellite's bucket (the newest creation per granule)."""
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

    def fetch(self, f: ListedFile) -> Path:
        """The cached copy of *f*, downloaded (bounded, checked against the listing) if missing."""
        folder = self.cache_dir / f.product
        folder.mkdir(parents=True, exist_ok=True)
        target = folder / f.name  # f.name is a checked base name: it cannot leave the cache
        if target.exists() and (f.size is None or target.stat().st_size == f.size):
            return target
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
            except SourceError as exc:
                last = exc
                part.unlink(missing_ok=True)
                if attempt < self.cfg.retries and "refused" not in str(exc) and "deadline" not in str(exc):
                    LOG.warning("download of %s failed (attempt %d): %s", f.name, attempt + 1, exc)
                    self.sleep(min(self.cfg.backoff_s * 2**attempt, self._left_s(f.name)))
                    continue
                break
            self.spent_bytes += n
            self.downloaded_files += 1
            os.replace(part, target)
            return target
        raise SourceError(f"{f.name}: download failed ({last})")

    def _download(self, url: str, f: ListedFile, part: Path) -> int:
        """One download into *part*: bounded in bytes and time, checked against the listing."""
        r = self._get(url, f.name, stream=True)
        try:
            encoding = r.headers.get("Content-Encoding", "identity").strip().lower()
            if encoding not in ("", "identity"):
                raise SourceError(f"{f.name}: compressed response (Content-Encoding {encoding[:20]}) refused")
            length = r.headers.get("Content-Length")
            if f.size is not None and length is not None and length.strip() != str(f.size):
                raise SourceError(f"{f.name}: Content-Length {length[:20]}, the listing says {f.size}")
            slowest = time.monotonic() + 30.0 + (f.size or 0) / (self.cfg.min_rate_kb_s * 1e3)
            md5 = hashlib.md5() if f.md5 else None
            n = 0
            with open(part, "wb") as out:
                while True:
                    try:
                        chunk = r.raw.read1(1 << 20, decode_content=False)
                    except (
                        requests.RequestException,
                        urllib3.exceptions.HTTPError,
                        OSError,
                        ValueError,
                    ) as exc:
                        raise SourceError(f"{f.name}: {type(exc).__name__} after {n} bytes") from None
                    if not chunk:
                        break
                    n += len(chunk)
                    if f.size is not None and n > f.size:
                        raise SourceError(f"{f.name}: more than the {f.size} bytes listed")
                    if time.monotonic() > slowest:
                        raise SourceError(
                            f"{f.name}: slower than {self.cfg.min_rate_kb_s:g} kB/s ({n} bytes received)"
                        )
                    self._left_s(f.name)
                    out.write(chunk)
                    if md5 is not None:
                        md5.update(chunk)
                out.flush()
                os.fsync(out.fileno())
        finally:
            r.close()
        if f.size is not None and n != f.size:
            raise SourceError(f"{f.name}: got {n} bytes, the listing says {f.size}")
        if md5 is not None and md5.hexdigest() != f.md5:
            raise SourceError(f"{f.name}: MD5 {md5.hexdigest()} differs from the listing's ETag {f.md5}")
        return n


def _newest_per_granule(files: list[ListedFile]) -> list[ListedFile]:
    """Reprocessed granules reappear with a newer creation time: keep the newest of each."""
    best = {}
    for f in files:
        key = (f.product, f.parsed.granule_key)
        if key not in best or best[key].parsed.created < f.parsed.created:
            best[key] = f
    return sorted(best.values(), key=lambda f: (f.parsed.start, f.product))
