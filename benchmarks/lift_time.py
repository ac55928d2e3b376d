"""What lifting one VIIRS granule's pixels to their cloud heights costs: the clear-sky reference and the
lift (``monitor.collocation.lift.lift_m``), then the lifted points (``monitor.collocation.lift.lifted``),
on 1 and 2 threads.

    python -m benchmarks.lift_time --data DIR [--granule 3] [--repeat 3] [--rows FILE]

*data* is a simulated case (``crisgeo simulate``, ``benchmarks.day_memory --data``); the granule is the
*granule*-th VIIRS granule of its plan, read whole. The kernels are compiled (or loaded from numba's cache)
on a few scans first. Printed: the median seconds of *repeat* calls, and a checksum of the lifted points
so that two codes can be compared for the same numbers.
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.inputs import read_viirs
from monitor.collocation import lift as pixel_lift
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.sdr.pairing import plan


def _median_s(call: Callable[[], object], repeat: int) -> float:
    """The median wall seconds of *repeat* calls of *call*."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--data", required=True)
    p.add_argument("--granule", type=int, default=3)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--rows", help="append the JSON row here")
    args = p.parse_args()
    case = plan([Path(args.data)])
    geo, sdr, _, _ = read_viirs(case.viirs_all[args.granule], case.viirs_all)
    assert geo.height_m is not None
    lat, lon, h = geo.lat_rad, geo.lon_rad, geo.height_m
    few = slice(0, 64)  # two scans: compiled here, not timed
    ones = np.ones_like(sdr.bt_k[few])
    pixel_lift.lifted(lat[few], lon[few], h[few], ones, geo.sc_position_m[:2], geo.sc_velocity_m_s[:2])
    lift = pixel_lift.lift_m(sdr.bt_k, sdr.good, PROBE_M_PER_K)
    row = {
        "commit": commit(),
        "pixels": int(lift.size),
        "lifted_share": round(float(np.mean(lift > 0)), 3),
        "lift_m_s": round(
            _median_s(lambda: pixel_lift.lift_m(sdr.bt_k, sdr.good, PROBE_M_PER_K), args.repeat), 2
        ),
    }
    args_lifted = (lat, lon, h, lift, geo.sc_position_m, geo.sc_velocity_m_s)
    for threads in (1, 2):
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        row[f"lifted_s_{threads}_threads"] = round(
            _median_s(lambda: pixel_lift.lifted(*args_lifted), args.repeat), 2
        )
    points = pixel_lift.lifted(*args_lifted)
    row["checksum"] = hashlib.sha256(b"".join(np.ascontiguousarray(a).tobytes() for a in points)).hexdigest()[
        :16
    ]
    emit(row, args.rows)


if __name__ == "__main__":
    main()
