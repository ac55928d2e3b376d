"""What the parallax stage costs per VIIRS granule: the clear-sky reference and the heights, and the
rendering of what each CrIS FOV row sees (``monitor.collocation.render.rendered_bt`` at the probe's
kappa, for :data:`monitor.collocation.render.VIEW_ALPHA_RAD`), on 1 and 2 threads.

    python -m benchmarks.lift_time --data DIR [--granule 3] [--repeat 3] [--rows FILE]

*data* is a simulated case (``crisgeo simulate``, ``benchmarks.day_memory --data``); the granule is the
*granule*-th VIIRS granule of its plan, read whole. The kernels are compiled (or loaded from numba's cache)
on a few scans first. Printed: the median seconds of *repeat* calls, and a checksum of the rendered BT so
that two codes can be compared for the same numbers. Rows before 2026-11-28 timed the point lift
(``lift_m_s``, ``lifted_s_*``), which the rendering replaced.
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
from monitor.collocation import render
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
    fields = (geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good)
    spacecraft = (geo.sc_position_m, geo.sc_velocity_m_s)
    few = slice(0, 64)  # two scans: compiled here, not timed
    lat, lon, h, bt, good = (a[few] for a in fields)
    sat, velocity = (a[:2] for a in spacecraft)
    render.rendered_bt(lat, lon, h, bt, good, sat, velocity, render.VIEW_ALPHA_RAD, PROBE_M_PER_K)
    row: dict = {"commit": commit(), "pixels": int(sdr.bt_k.size), "views": len(render.VIEW_ALPHA_RAD)}
    for threads in (1, 2):
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        row[f"rendered_s_{threads}_threads"] = round(
            _median_s(
                lambda: render.rendered_bt(*fields, *spacecraft, render.VIEW_ALPHA_RAD, PROBE_M_PER_K),
                args.repeat,
            ),
            2,
        )
    seen = render.rendered_bt(*fields, *spacecraft, render.VIEW_ALPHA_RAD, PROBE_M_PER_K)
    row["checksum"] = hashlib.sha256(np.ascontiguousarray(seen).tobytes()).hexdigest()[:16]
    emit(row, args.rows)


if __name__ == "__main__":
    main()
