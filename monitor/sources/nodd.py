"""NOAA Open Data Dissemination (NODD) buckets over plain HTTPS: anonymous ListObjectsV2 and GET.

Keys are ``<product folder>/YYYY/MM/DD/<file>``, e.g. ``CrIS-SDR-GEO/2024/06/01/GCRSO_j01_...h5``
(operations.md 1.2). Listings are narrowed with a file-name prefix and followed through continuation
tokens (a day holds more than the 1000 keys of one page). Downloads go to ``<name>.part`` and are
renamed only when complete and of the listed size; a dropped connection is retried with backoff. A
per-day byte budget bounds what one run may download, and cached files older than the retention go.
"""

from __future__ import annotations

import datetime as dt
import logging
import os
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import requests
from requests.adapters import HTTPAdapter
from urllib3.util.retry import Retry

from monitor.sources import BudgetExceeded, ListedFile, SourceError, listed

LOG = logging.getLogger(__name__)
S3_NS = "{http://s3.amazonaws.com/doc/2006-03-01/}"
FOLDERS = {"SCRIF": "CrIS-FS-SDR", "SCRIS": "CrIS-SDR", "GCRSO": "CrIS-SDR-GEO", "SVI05": "VIIRS-I5-SDR",
           "GITCO": "VIIRS-IMG-GEO-TC", "GIMGO": "VIIRS-IMG-GEO"}
CRIS = ("SCRIF", "SCRIS", "GCRSO")


class NoddSource:
    """Granules of the NODD bucket of each satellite, cached under *cache_dir*."""

    def __init__(self, cfg, cache_dir: Path):
        self.cfg = cfg
        self.cache_dir = Path(cache_dir)
        self.session = requests.Session()
        retry = Retry(total=cfg.retries, backoff_factor=cfg.backoff_s, status_forcelist=(429, 500, 502, 503, 504),
                      allowed_methods=("GET", "HEAD"), respect_retry_after_header=True)
        self.session.mount("http://", HTTPAdapter(max_retries=retry))
        self.session.mount("https://", HTTPAdapter(max_retries=retry))
        self.spent_bytes = 0

    def _base(self, satellite: str) -> str:
        bucket = self.cfg.buckets.get(satellite)
        if bucket is None:
            raise SourceError(f"no NODD bucket configured for {satellite}")
        return self.cfg.endpoint.format(bucket=bucket).rstrip("/")

    def start_day(self):
        """Reset the day's budget and apply the cache retention."""
        self.spent_bytes = 0
        self.cache_dir.mkdir(parents=True, exist_ok=True)
        cutoff = time.time() - self.cfg.retention_days * 86400
        for p in self.cache_dir.rglob("*"):
            if p.is_file() and (p.suffix == ".part" or p.stat().st_mtime < cutoff):
                p.unlink(missing_ok=True)

    def list_prefix(self, satellite: str, prefix: str) -> list[ListedFile]:
        """Every object under *prefix*, following continuation tokens."""
        out, token = [], None
        base = self._base(satellite)
        while True:
            params = {"list-type": "2", "prefix": prefix, "max-keys": "1000"}
            if token:
                params["continuation-token"] = token
            try:
                r = self.session.get(base + "/", params=params, timeout=self.cfg.timeout_s)
            except requests.RequestException as exc:
                raise SourceError(f"listing {prefix}: {type(exc).__name__}") from None
            if r.status_code != 200:
                raise SourceError(f"listing {prefix}: HTTP {r.status_code}")
            try:
                root = ET.fromstring(r.content)
            except ET.ParseError as exc:
                raise SourceError(f"listing {prefix}: invalid XML ({exc})") from None
            for c in root.iter(f"{S3_NS}Contents"):
                key = c.findtext(f"{S3_NS}Key") or ""
                size = c.findtext(f"{S3_NS}Size")
                f = listed(key.rsplit("/", 1)[-1], int(size) if size and size.isdigit() else None, key)
                if f is None or not key.startswith(prefix):
                    LOG.warning("ignoring listed key %r: not a JPSS granule under %s", key, prefix)
                    continue
                out.append(f)
            if (root.findtext(f"{S3_NS}IsTruncated") or "").lower() != "true":
                return out
            token = root.findtext(f"{S3_NS}NextContinuationToken")
            if not token:
                raise SourceError(f"listing {prefix}: truncated without a continuation token")

    def list_day(self, satellite: str, day: dt.date, products) -> list[ListedFile]:
        out = []
        for product in products:
            folder = FOLDERS[product]
            prefixes = [(day, f"{product}_{satellite}_d{day:%Y%m%d}")]
            if product not in CRIS:  # VIIRS granules spanning midnight cover the day's first/last CrIS
                prev, nxt = day - dt.timedelta(days=1), day + dt.timedelta(days=1)
                prefixes += [(prev, f"{product}_{satellite}_d{prev:%Y%m%d}_t23"),
                             (nxt, f"{product}_{satellite}_d{nxt:%Y%m%d}_t00")]
            for d, name_prefix in prefixes:
                out += self.list_prefix(satellite, f"{folder}/{d:%Y/%m/%d}/{name_prefix}")
        return _newest_per_granule(out)

    def fetch(self, f: ListedFile) -> Path:
        folder = self.cache_dir / f.product
        folder.mkdir(parents=True, exist_ok=True)
        target = folder / f.name  # f.name is a checked base name: it cannot leave the cache
        if target.exists() and (f.size is None or target.stat().st_size == f.size):
            return target
        if f.size is not None and self.spent_bytes + f.size > self.cfg.daily_budget_mb * 1e6:
            raise BudgetExceeded(f"{f.name}: the day's download budget of {self.cfg.daily_budget_mb:.0f} MB is spent")
        part = target.with_name(target.name + ".part")
        url = f"{self._base(f.parsed.platform)}/{f.location}"
        last = None
        for attempt in range(self.cfg.retries + 1):
            if attempt:
                time.sleep(min(self.cfg.backoff_s * 2 ** (attempt - 1), 60.0))
            try:
                with self.session.get(url, stream=True, timeout=self.cfg.timeout_s) as r:
                    if r.status_code != 200:
                        raise SourceError(f"{f.name}: HTTP {r.status_code}")
                    n = 0
                    with open(part, "wb") as out:
                        for chunk in r.iter_content(1 << 20):
                            out.write(chunk)
                            n += len(chunk)
                        out.flush()
                        os.fsync(out.fileno())
                self.spent_bytes += n
                if f.size is not None and n != f.size:
                    raise SourceError(f"{f.name}: got {n} bytes, the listing says {f.size}")
                os.replace(part, target)
                return target
            except (requests.RequestException, SourceError) as exc:
                last = exc
                LOG.warning("download of %s failed (attempt %d): %s", f.name, attempt + 1, exc)
                part.unlink(missing_ok=True)
        raise SourceError(f"{f.name}: download failed after {self.cfg.retries + 1} attempts ({last})")


def _newest_per_granule(files: list[ListedFile]) -> list[ListedFile]:
    """Reprocessed granules reappear with a newer creation time: keep the newest of each."""
    best = {}
    for f in files:
        key = (f.product, f.parsed.granule_key)
        if key not in best or best[key].parsed.created < f.parsed.created:
            best[key] = f
    return sorted(best.values(), key=lambda f: (f.parsed.start, f.product))
