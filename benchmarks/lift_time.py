"""What drawing one VIIRS granule as the CrIS FOV rows see it costs: the pixels' heights over the clear-sky
reference, their view tangents, the columns sorted along the track and rendered for each of the three rows
(``monitor.collocation.render.rendered_bt``), on 1 and 2 threads.

    python -m benchmarks.lift_time --data DIR [--granule 3] [--repeat 3] [--rows FILE]

*data* is a simulated case (``crisgeo simulate``, ``benchmarks.day_memory --data``); the granule is the
*granule*-th VIIRS granule of its plan, read whole. The kernels are compiled (or loaded from numba's cache)
on a few scans first. Printed: the median seconds of *repeat* calls, the share of pixels standing above
their GEO points, and a checksum of the rendered BT so that two codes can be compared for the same
numbers. The rows before 0285fa0 timed the point lift this replaced (``lifted_s_*``).
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
from monitor.collocation import lift, render
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.sdr.pairing import plan

ROW_ALPHA_RAD = np.array([-0.0191, 0.0, 0.0191])  # the CrIS FOV rows' in-track angles, behind to ahead


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
    lat, lon, h, bt, good = geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good
    sat, vel = geo.sc_position_m, geo.sc_velocity_m_s

    def rendered(rows: slice = slice(None), scans: slice = slice(None)) -> np.ndarray:
        return render.rendered_bt(
            lat[rows], lon[rows], h[rows], bt[rows], good[rows], sat[scans], vel[scans], ROW_ALPHA_RAD,
            PROBE_M_PER_K,
        )  # fmt: skip

    rendered(slice(0, 64), slice(0, 2))  # two scans: compiled here, not timed
    height = lift.height_above_m(sdr.bt_k, sdr.good, lift.reference_k(sdr.bt_k, sdr.good), PROBE_M_PER_K)
    row = {
        "commit": commit(),
        "pixels": int(height.size),
        "lifted_share": round(float(np.mean(height > 0)), 3),
    }
    for threads in (1, 2):
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
        row[f"rendered_s_{threads}_threads"] = round(_median_s(rendered, args.repeat), 2)
    seen = rendered()
    row["checksum"] = hashlib.sha256(np.ascontiguousarray(seen).tobytes()).hexdigest()[:16]
    emit(row, args.rows)


if __name__ == "__main__":
    main()
