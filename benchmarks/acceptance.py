"""Full-size acceptance runs of the science core: recovery of injected offsets on simulated cases.

For each profile (paper, random, zero), seed and case size (the paper's 14 granules, and 6), simulate,
assess, and print the RMS and the largest error over the 30 FORs in each direction against the
acceptance bounds (RMS <= 60 urad, every FOR within 150 urad). Slow (~3 min per 14-granule case);
not part of the test suite.

    .venv/bin/python benchmarks/acceptance.py [--sizes 14 6] [--seeds 1 2] [--profiles paper random zero]
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from monitor.assess import AssessConfig, assess_paths
from monitor.simulate.case import simulate_case


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[14, 6])
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    p.add_argument("--profiles", nargs="+", default=["paper", "random", "zero"])
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--keep", help="directory to keep the cases and results in")
    args = p.parse_args()
    root = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="crisgeo-acceptance-"))
    failures = 0
    print(f"{'profile':<8} {'seed':>4} {'gran':>4} {'rms_a':>6} {'max_a':>6} {'rms_b':>6} {'max_b':>6} "
          f"{'flagged':>7} {'assess_s':>8}  verdict")
    for size in args.sizes:
        for profile in args.profiles:
            for seed in args.seeds:
                case = root / f"{profile}_{seed}_{size}"
                truth = simulate_case(case, granules=size, profile=profile, seed=seed)
                t0 = time.perf_counter()
                result = assess_paths([case], AssessConfig(), workers=args.workers)
                secs = time.perf_counter() - t0
                (case / "result.json").write_text(result.to_json(with_cube=False))
                ta = np.array([f["d_alpha_urad"] for f in truth["fors"]])
                tb = np.array([f["d_beta_urad"] for f in truth["fors"]])
                ea = np.array([f.d_alpha_urad for f in result.fors]) - ta
                eb = np.array([f.d_beta_urad for f in result.fors]) - tb
                flagged = sum(not f.reliable for f in result.fors)
                rms_a, rms_b = np.sqrt(np.mean(ea**2)), np.sqrt(np.mean(eb**2))
                ok = max(rms_a, rms_b) <= 60 and max(np.abs(ea).max(), np.abs(eb).max()) <= 150
                failures += not ok
                print(f"{profile:<8} {seed:>4} {size:>4} {rms_a:6.1f} {np.abs(ea).max():6.1f} {rms_b:6.1f} "
                      f"{np.abs(eb).max():6.1f} {flagged:>7} {secs:8.1f}  {'pass' if ok else 'FAIL'}", flush=True)
                if not args.keep:
                    shutil.rmtree(case)
    print(f"{failures} case(s) out of bounds")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
