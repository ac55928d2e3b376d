"""Peak memory of a long simulated day assessed in batches: does it grow with the granules?

    python -m benchmarks.day_memory [--granules 100] [--keep 14] [--seed 1] [--data DIR] [--rows FILE]

A day of *granules* simulated CrIS granules (clouds on the ground, the paper profile; simulated in *data*
once and reused) is collocated by a :class:`~monitor.assessment.assess.DayAssessment` in batches of *keep*,
as the daily run does with a precision target, with the default configuration (the footprint kernel and
the parallax probe: both collocations of each granule in one pass). The estimate is made after the first
batch (the paper's 14-granule day) and after the last. Printed: the process's peak resident memory (VmHWM,
the simulation's reset away) after each, and the seconds. The daily run re-estimates after every batch;
the estimate's memory is that of its granule count, so the last one is the peak either way.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

from benchmarks.provenance import commit, emit
from monitor.assessment.assess import DayAssessment
from monitor.assessment.bench import peak_rss_mb, reset_peak_rss
from monitor.collocation.collocate import warm_up
from monitor.config.assessment import AssessmentConfig
from monitor.sdr.pairing import plan
from monitor.simulate.case import simulate_case


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--granules", type=int, default=100)
    p.add_argument("--keep", type=int, default=14)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--data", help="simulate the case here, or reuse the one simulated here before")
    p.add_argument("--rows", help="append the JSON row here")
    args = p.parse_args()
    cfg = AssessmentConfig()
    with tempfile.TemporaryDirectory(prefix="crisgeo-memory-") as tmp:
        data = Path(args.data or tmp)
        t0 = time.perf_counter()
        if not (data / "truth.json").exists():
            simulate_case(data, granules=args.granules, profile="paper", seed=args.seed)
        simulated_s = time.perf_counter() - t0
        warm_up()
        if not reset_peak_rss():
            raise SystemExit(
                "this system cannot reset the peak memory count: the simulation's would be counted"
            )
        case = plan([data])
        points: list[dict[str, Any]] = []
        t0 = time.perf_counter()
        with DayAssessment(case.satellite, cfg, cfg.workers) as day:
            for first in range(0, len(case.cris), args.keep):
                cris = case.cris[first : first + args.keep]
                batch = {g.key: case.viirs[g.key] for g in cris}
                day.add(replace(case, cris=cris, viirs=batch, skipped=[]))
                if first == 0 or first + args.keep >= len(case.cris):
                    result = day.result()
                    points.append(
                        {
                            "granules": len(result.granules),
                            "peak_mb": round(peak_rss_mb()),
                            "seconds": round(time.perf_counter() - t0, 1),
                            "day_sigma_urad": result.day_sigma_urad(),
                        }
                    )
                    print(points[-1], flush=True)
    emit(
        {
            "commit": commit(),
            "granules": args.granules,
            "keep": args.keep,
            "seed": args.seed,
            "workers": cfg.workers,
            "simulation_s": round(simulated_s, 1),
            "points": points,
            "growth": round(points[-1]["peak_mb"] / points[0]["peak_mb"], 3),
        },
        args.rows,
    )


if __name__ == "__main__":
    main()
