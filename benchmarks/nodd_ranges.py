"""Bytes from NODD: a satellite-day read in place (``source.read: ranges``) against whole files.

Real-size simulated granules with every dataset of the real products (``SimulationSpec.complete``: GITCO
~325 MB, SVI05 ~49 MB, SCRIF ~19 MB, GCRSO ~0.1 MB uncompressed), in either HDF5 layout (contiguous, as
uncompressed IDPS files; gzip with one chunk per dataset, as the real GCRSO), are put under their NODD
keys on moto's S3 server on loopback. Each case then runs the daily job
(:func:`monitor.service.pipeline.run_day`: list, fingerprint, select, assess, record) three times, each into
an empty store: whole files into an empty cache, ranges into an empty cache, and ranges again on that
cache. It prints, per run: bytes read, their share of the bytes of the files the day used, HTTP
requests (listings included) and wall time; per product, the bytes read in place (from the block
lists); and whether the offsets are the whole-file run's to the bit.

Loopback moves ~250 MB/s, and moto answers each range by reading the whole object (~0.25 s per request
on a GITCO; S3 answers in tens of ms): so the transfer time is also projected at 100 MB/s and 30 ms per
request, the figures assumed for NODD.

    .venv/bin/python -m benchmarks.nodd_ranges [--granules 1 14] [--layouts contiguous gzip] [--keep DIR]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import platform
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit
from benchmarks.servers import MotoS3
from monitor.archive.configured import make_source
from monitor.archive.ranged import BLOCK_BYTES, BLOCK_LIST, RANGES_FOLDER
from monitor.collocation.collocate import warm_up
from monitor.config.file import load_config
from monitor.core.satellites import SATELLITES
from monitor.service.pipeline import RunOutcome, run_day
from monitor.service.store.sqlite import Store
from monitor.simulate import LAYOUTS
from monitor.simulate.case import DEFAULT_START, simulate_case

SATELLITE = "j01"
DAY = DEFAULT_START.date()
PROJECTED_B_S, PROJECTED_REQUEST_S = 100e6, 0.03
RESULTS = Path(__file__).parent / "results"


def simulate(root: Path, granules: int, layout: str) -> list[Path]:
    """The case's files (simulated once into *root*, then reused)."""
    out = root / f"{layout}_{granules}"
    if not (out / "truth.json").exists():
        shutil.rmtree(out, ignore_errors=True)
        simulate_case(
            out, satellite=SATELLITE, granules=granules, profile="paper", seed=1, complete=True,
            layout=layout,
        )  # fmt: skip
    return [out / n for n in json.loads((out / "truth.json").read_text())["files"]]


def run(root: Path, url: str, name: str, read: str, granules: int) -> tuple[RunOutcome, float]:
    """compute_day on the bucket, from an empty store (the cache kept across runs of one *name*)."""
    state = root / name / "state"
    state.mkdir(parents=True, exist_ok=True)
    for p in state.iterdir():  # an empty store, the cache kept
        if p.name != "cache":
            shutil.rmtree(p) if p.is_dir() else p.unlink()
    config = root / f"{name}.yaml"
    config.write_text(
        f"satellites: [{SATELLITE}]\nstate_dir: {state}\n"
        f"source: {{kind: nodd, endpoint: '{url}/{{bucket}}', read: {read}, daily_budget_mb: 100000}}\n"
        f"scenes: {{min_inhomogeneity_k: 0, keep: {granules}}}\nfingerprint: {{granules: 2}}\n"
    )
    cfg = load_config(config)
    t0 = time.perf_counter()
    assert cfg.store.sqlite is not None  # the state folder's store
    with Store(cfg.store.sqlite) as store:
        out = run_day(cfg, store, make_source(cfg), SATELLITE, DAY, dt.date.today())
        (recorded,) = store.runs()
    assert recorded.status == out.status  # the run is in the ledger as it says
    return out, time.perf_counter() - t0


def held_by_product(cache: Path) -> dict:
    """Bytes held in the block cache per product (blocks recorded x block size, the last block capped)."""
    out: dict[str, int] = {}
    for listing in (cache / RANGES_FOLDER).rglob(f"*{BLOCK_LIST}"):
        record = json.loads(listing.read_text())
        blocks = record["blocks"]
        n = len(blocks) * BLOCK_BYTES
        if blocks and max(blocks) == (record["size"] - 1) // BLOCK_BYTES:
            n -= (-record["size"]) % BLOCK_BYTES
        product = listing.parent.name
        out[product] = out.get(product, 0) + n
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--granules", type=int, nargs="+", default=[1, 14])
    ap.add_argument("--layouts", nargs="+", default=list(LAYOUTS), choices=LAYOUTS)
    ap.add_argument("--keep", help="directory for the simulated cases (kept; reused when present)")
    ap.add_argument("--out", default=str(RESULTS / f"nodd_ranges_{dt.date.today()}.jsonl"))
    args = ap.parse_args(argv)
    root = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="crisgeo-nodd-"))
    root.mkdir(parents=True, exist_ok=True)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; work in {root}")
    print(f"kernels compiled or loaded in {warm_up():.1f} s (not timed)")
    rows = []
    for layout in args.layouts:
        for granules in args.granules:
            t0 = time.perf_counter()
            files = simulate(root, granules, layout)
            sizes = {f.name.split("_")[0]: 0 for f in files}
            for f in files:
                sizes[f.name.split("_")[0]] += f.stat().st_size
            listing = ", ".join(f"{p} {n / 1e6:.1f} MB" for p, n in sorted(sizes.items()))
            ready_s = time.perf_counter() - t0
            print(f"\n{layout}, {granules} CrIS granule(s): {len(files)} files, "
                  f"{sum(sizes.values()) / 1e6:.0f} MB ({listing}); ready in {ready_s:.0f} s")  # fmt: skip
            case = root / f"run_{layout}_{granules}"
            shutil.rmtree(case, ignore_errors=True)
            with MotoS3() as s3:
                s3.put_granules(SATELLITES[SATELLITE].bucket, files)
                whole, whole_s = run(case, s3.url, "whole", "whole", granules)
                first, first_s = run(case, s3.url, "ranges", "ranges", granules)
                held = held_by_product(case / "ranges" / "state" / "cache")
                again, again_s = run(case, s3.url, "ranges", "ranges", granules)
            total = sum(sizes.values())
            same = (
                whole.result is not None
                and first.result is not None
                and [f.to_dict() for f in whole.result.fors] == [f.to_dict() for f in first.result.fors]
                and np.array_equal(np.asarray(whole.result.cost_cube_k), np.asarray(first.result.cost_cube_k))
            )
            for label, w, secs in (
                ("whole", whole, whole_s),
                ("ranges", first, first_s),
                ("ranges again", again, again_s),
            ):
                n, req = w.counts.bytes, w.counts.requests
                projected = n / PROJECTED_B_S + req * PROJECTED_REQUEST_S
                compute = sum(v for k, v in w.timings.items() if k not in ("fetch",))
                row = {
                    "commit": commit(),
                    "layout": layout, "granules": granules, "run": label, "status": str(w.status),
                    "assessed": w.counts.assessed, "bytes": n, "files_bytes": total,
                    "share": n / total, "requests": req, "wall_s": round(secs, 1),
                    "projected_transfer_s": round(projected, 1),
                    "timings_s": {k: round(v, 1) for k, v in w.timings.items()},
                }  # fmt: skip
                if label == "ranges":
                    row |= {"held_by_product": held, "same_bits_as_whole": same}
                rows.append(row)
                print(f"  {label:13s} {w.status:8s} {w.counts.assessed:2d} assessed  {n / 1e6:8.1f} MB "
                      f"({100 * n / total:5.1f} % of the files)  {req:5d} requests  {secs:6.1f} s  "
                      f"(transfer at 100 MB/s + 30 ms/request: {projected:5.1f} s; other stages "
                      f"{compute:.1f} s)")  # fmt: skip
            print("  read in place, by product: " + ", ".join(
                f"{p} {held.get(p, 0) / 1e6:.1f} of {sizes[p] / 1e6:.1f} MB "
                f"({100 * held.get(p, 0) / sizes[p]:.0f} %)"
                for p in sorted(sizes)
            ))  # fmt: skip
            print(f"  offsets read in place = whole files, to the bit: {same}")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "a") as fh:
        for row in rows:
            fh.write(json.dumps(row) + "\n")
    print(f"\nrows appended to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
