"""A NODD granule read in place: HTTP range requests through a block cache on local disk.

h5py reads the granule through a file object (:class:`RangedReader`), so only the bytes of the HDF5
structure and of the datasets (and, for VIIRS, the scans) the pipeline asks for travel. The bytes live in
fsspec's block cache on disk (:class:`fsspec.caching.MMapCache`, the store of fsspec's own ``blockcache``
file system): a sparse file of the object's listed size under ``<cache_dir>/ranges/<product>/<name>``,
filled block by block, with the numbers of the blocks held in ``<name>.blocks`` beside it. A read fetches
the missing blocks it covers, consecutive ones in one request (:meth:`NoddSource.read_range`, under every
bound of a download). A rerun, or a second satellite-day sharing a VIIRS granule, reads them from disk.

Why not fsspec's HTTP or S3 file systems (or obstore) for the transport: their timeouts bound socket
operations, not requests; they know nothing of the stall window, the listed size, the day's budget or
the same-host rule of redirects that every NODD request obeys here. The transport stays the NODD source's;
fsspec provides the cache.

What is trusted and when:

* A block list is written only after its blocks are on disk (``msync``), only by a reader whose every
  read succeeded (fsspec marks blocks held before it fetches them; a failed read leaves the reader
  failed and its list unwritten), merged with what other readers wrote under a lock on the file, and
  tied to the file's inode (a list outliving its file, evicted and made anew, is ignored).
* Each range is exactly the bytes asked for, of an object of the listed size (Content-Range).
* A granule of one block (a GCRSO) is fetched whole by its first read, and its MD5 checked against the
  listing's ETag before any byte is used; so is any granule once all its blocks are held.
* The rest is checked by the readers: the HDF5 structure, every value against the product table and the
  physics (a corrupt range is a GranuleError naming the key, never a silent number).
"""

from __future__ import annotations

import contextlib
import fcntl
import gc
import hashlib
import io
import json
import os
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fsspec.caching import MMapCache

from monitor.archive import ListedFile, SourceError

BLOCK_BYTES = 1 << 20  # 1 MiB: HDF5 metadata and the start and end of each array cost at most a block each
RANGES_FOLDER = "ranges"
BLOCK_LIST = ".blocks"

Fetch = Callable[[ListedFile, int, int], bytes]


class _CyclicGcPaused:
    """Automatic cyclic garbage collection held off while any thread is inside (nesting, across threads).

    h5py calls :class:`RangedReader` holding its global lock, and a fetch waits for threads of its own (the
    request's watchdog, :meth:`monitor.archive.bounded.BoundedSession.guard`). A collection that starts on
    such a thread and frees an h5py object waits for that lock: both threads then wait for ever (h5py issue
    2019; seen here in a CI run as a watchdog that never started). Explicit ``gc.collect()`` still runs."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._inside = 0
        self._was_enabled = False

    @contextlib.contextmanager
    def __call__(self) -> Iterator[None]:
        with self._lock:  # nothing allocated under it: no collection can start here
            self._inside += 1
            if self._inside == 1:
                self._was_enabled = gc.isenabled()
                gc.disable()
        try:
            yield
        finally:
            with self._lock:
                self._inside -= 1
                if self._inside == 0 and self._was_enabled:
                    gc.enable()


no_cyclic_gc = _CyclicGcPaused()


def forget(path: Path) -> None:
    """Remove a cached file and its block list (a download, or a granule read in place).

    Parameters
    ----------
    path : Path
        The cached file.
    """
    path.unlink(missing_ok=True)
    Path(f"{path}{BLOCK_LIST}").unlink(missing_ok=True)


@dataclass(frozen=True)
class RangedGranule:
    """A listed NODD granule to read in place (a :class:`monitor.sdr.granules.RemoteGranule`): *fetch*
    brings one byte range (the NODD source's bounded range request), *root* holds the block cache."""

    listed: ListedFile
    fetch: Fetch
    root: Path

    @property
    def name(self) -> str:  # numpydoc ignore=RT01
        """The granule's file name."""
        return self.listed.name

    def __str__(self) -> str:
        return self.listed.location  # errors name the key

    def open(self) -> RangedReader:
        """A file object over the granule's bytes, through the block cache.

        Returns
        -------
        RangedReader
            The file object.
        """
        return RangedReader(self)


class RangedReader(io.RawIOBase):
    """A seekable binary file over a remote granule; what is read is fetched through the block cache.

    A failed fetch leaves the reader failed: ``failure`` names the key, the range and the reason, every
    further read raises, and nothing it fetched is recorded as held.

    Parameters
    ----------
    granule : RangedGranule
        The granule read.
    """

    def __init__(self, granule: RangedGranule):
        super().__init__()
        f = granule.listed
        if f.size is None:
            raise SourceError(f"{f.location}: no listed size, so it cannot be read in place")
        self.granule, self.size = granule, f.size
        self.failure: str | None = None
        self.pos = 0
        self.path = granule.root / f.product / f.name
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            blocks, self.verified = self._held()
            self._create()
            self.cache = MMapCache(
                BLOCK_BYTES, self._fetch, f.size, location=str(self.path), blocks=set(blocks)
            )
            os.utime(self.path)  # used now: the cache bound evicts the least recently used first
            self.inode = os.stat(self.path).st_ino
            if self.inode != self._held_inode:  # evicted and made anew since the record was read
                self.cache.blocks.clear()
                self.verified = False
        except (OSError, ValueError) as exc:
            raise SourceError(f"{f.location}: block cache {self.path}: {exc}") from None
        self.n_blocks = -(-f.size // BLOCK_BYTES)

    def _held(self) -> tuple[list[int], bool]:
        """The blocks a previous reader recorded for this very file (same size, block size, MD5 and
        inode); none when there is no such record (the file's bytes are then fetched again as read)."""
        f, listing = self.granule.listed, Path(f"{self.path}{BLOCK_LIST}")
        self._held_inode = -1
        try:
            st = os.stat(self.path)
        except FileNotFoundError:
            return [], False
        if st.st_size != f.size:
            forget(self.path)  # not this object's file: start it anew
            return [], False
        try:
            held = json.loads(listing.read_text())
            if (held["size"], held["block_bytes"], held["inode"], held["md5"]) == (
                f.size,
                BLOCK_BYTES,
                st.st_ino,
                f.md5,
            ):
                self._held_inode = st.st_ino
                return [int(b) for b in held["blocks"]], bool(held["verified"])
        except (OSError, ValueError, KeyError, TypeError):
            pass
        return [], False

    def _create(self) -> None:
        """The sparse file of the object's size, made atomically: fsspec would open a missing file with
        "wb+", truncating one that another reader has just made and mapped (its blocks would read as
        zeros)."""
        if self.path.exists():
            return
        tmp = self.path.with_name(f"{self.path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
        with open(tmp, "wb") as fh:
            fh.truncate(self.size)
        try:
            os.link(tmp, self.path)
        except FileExistsError:
            pass  # another reader made it first: share it
        finally:
            tmp.unlink(missing_ok=True)

    def _fetch(self, start: int, end: int) -> bytes:
        if start >= end:  # fsspec asks for the block after the last when a read ends on the file's end
            return b""
        return self.granule.fetch(self.granule.listed, start, end)

    # the file object h5py reads through
    def readable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def tell(self) -> int:
        return self.pos

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        base = {io.SEEK_SET: 0, io.SEEK_CUR: self.pos, io.SEEK_END: self.size}[whence]
        self.pos = max(0, base + offset)
        return self.pos

    def readinto(self, buffer: Any) -> int:  # a writable buffer (typeshed: Buffer)
        if self.failure is not None:
            raise OSError(self.failure)
        end = min(self.pos + len(buffer), self.size)
        if end <= self.pos:
            return 0
        try:
            with no_cyclic_gc():
                data = self.cache._fetch(self.pos, end)
            self._verify()
        except (SourceError, OSError, ValueError) as exc:
            self.failure = str(exc) if isinstance(exc, SourceError) else f"{self.granule}: {exc}"
            raise OSError(self.failure) from None
        n = len(data)
        buffer[:n] = data
        self.pos += n
        return n

    def _verify(self) -> None:
        """Once every block is held, the whole object against the listing's MD5 ETag (once per file)."""
        f = self.granule.listed
        if self.verified or f.md5 is None or not self.cache.blocks.issuperset(range(self.n_blocks)):
            return
        digest = hashlib.md5(self.cache.cache[: self.size]).hexdigest()
        if digest != f.md5:
            raise SourceError(
                f"{f.location}: MD5 {digest} of the blocks read differs from the listing's ETag {f.md5}"
            )
        self.verified = True

    def close(self) -> None:
        """Record the blocks held (if every read succeeded) and release the memory map."""
        if self.closed:
            return
        try:
            if self.failure is None and hasattr(self, "cache"):
                self._record()
        finally:
            cache = getattr(self, "cache", None)
            if cache is not None and not isinstance(cache.cache, bytearray):
                cache.cache.close()
            super().close()

    def _record(self) -> None:
        """Write the block list: after the blocks reach the disk, merged with other readers' under a lock
        on the cached file, for this file's inode only."""
        mm = self.cache.cache
        if isinstance(mm, bytearray):
            return
        mm.flush()
        listing = Path(f"{self.path}{BLOCK_LIST}")
        try:
            with open(self.path, "rb") as fh:
                fcntl.flock(fh, fcntl.LOCK_EX)
                if os.fstat(fh.fileno()).st_ino != self.inode:
                    return  # the file was evicted and made anew meanwhile: ours is gone
                blocks, verified = set(self.cache.blocks), self.verified
                with contextlib.suppress(OSError, ValueError, KeyError, TypeError):
                    held = json.loads(listing.read_text())
                    if held["inode"] == self.inode and held["block_bytes"] == BLOCK_BYTES:
                        blocks |= {int(b) for b in held["blocks"]}
                        verified = verified or bool(held["verified"])
                record = {
                    "size": self.size,
                    "block_bytes": BLOCK_BYTES,
                    "inode": self.inode,
                    "md5": self.granule.listed.md5,
                    "verified": verified,
                    "blocks": sorted(blocks),
                }
                tmp = listing.with_name(f"{listing.name}.{os.getpid()}.tmp")
                tmp.write_text(json.dumps(record))
                os.replace(tmp, listing)
        except FileNotFoundError:
            return  # evicted while we read: nothing to record
