"""A simulated day assessed to a precision target: the sigma of its first batch, then the day run again with
a target below it, batch by batch, to the reason it stopped, and its offsets against the truth.

    python -m benchmarks.precision_target [--granules 8] [--keep 4] [--fraction 0.75] [--clouds lapse:6.5]
                                          [--seed 41] [--data DIR] [--rows FILE]

The daily pipeline itself runs (``run_day`` on a local tree of the simulated granules, a store in a
temporary state directory): ranking, batches, the stop, the run summary. The target is *fraction* times
the sigma the first batch of *keep* granules reaches, rounded down to 0.1 urad, so the day needs about
keep / fraction^2 granules.
Every simulated granule is a candidate (``scenes.candidates`` and ``max_granules``); the other keys are the
defaults (``schedule.run_budget_min`` 240, ``source.daily_budget_mb``: simulated granules cost no bytes).
*data* keeps the simulated day for another run (simulated there once).
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.archive.local import LocalSource
from monitor.config.file import load_config
from monitor.service.pipeline import RunOutcome, run_day
from monitor.service.store.sqlite import Store
from monitor.simulate.case import simulate_case


def _day(root: Path, data: Path, name: str, keep: int, target: float | None, granules: int) -> RunOutcome:
    """One run of the daily pipeline over the simulated tree (*granules* of them, every one a candidate),
    with its own state directory."""
    state = root / name
    config = state / "c.yaml"
    state.mkdir()
    config.write_text(
        f"satellites: [j01]\nstate_dir: {state}\nsource: {{kind: local, path: {data}}}\n"
        f"scenes: {{keep: {keep}, candidates: {granules}, max_granules: {granules}, "
        f"target_sigma_urad: {'null' if target is None else target}}}\n"
    )
    cfg = load_config(config)
    assert cfg.store.sqlite is not None  # derived from state_dir
    truth_day = dt.date.fromisoformat(json.loads((data / "truth.json").read_text())["start"][:10])
    return run_day(cfg, Store(cfg.store.sqlite), LocalSource(data), "j01", truth_day, dt.date.today())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--granules", type=int, default=8)
    p.add_argument("--keep", type=int, default=4)
    p.add_argument("--fraction", type=float, default=0.75)
    p.add_argument("--clouds", default="lapse:6.5")
    p.add_argument("--seed", type=int, default=41)
    p.add_argument("--data", help="simulate the day here, or reuse the one simulated here before")
    p.add_argument("--rows", help="append the JSON row here")
    args = p.parse_args()
    with tempfile.TemporaryDirectory(prefix="crisgeo-precision-") as tmp:
        root = Path(tmp)
        data = Path(args.data) if args.data else root / "data"
        if (data / "truth.json").exists():
            truth = json.loads((data / "truth.json").read_text())
        else:
            truth = simulate_case(
                data, granules=args.granules, profile="random", seed=args.seed, cloud_heights=args.clouds
            )
        first = _day(root, data, "one-batch", args.keep, None, args.granules)
        assert first.precision is not None and first.precision.sigma_urad is not None, first.reason
        target = math.floor(10 * args.fraction * first.precision.sigma_urad) / 10  # at most the fraction
        t0 = time.perf_counter()
        day = _day(root, data, "target", args.keep, target, args.granules)
        seconds = time.perf_counter() - t0
    assert day.result is not None and day.precision is not None, day.reason
    ta = np.array([f["d_alpha_urad"] for f in truth["fors"]])
    tb = np.array([f["d_beta_urad"] for f in truth["fors"]])
    ea = np.array([f.d_alpha_urad for f in day.result.fors]) - ta
    eb = np.array([f.d_beta_urad for f in day.result.fors]) - tb
    emit(
        {
            "commit": commit(),
            "granules_simulated": args.granules,
            "keep": args.keep,
            "clouds": args.clouds,
            "seed": args.seed,
            "first_batch_sigma_urad": first.precision.sigma_urad,
            "target_sigma_urad": target,
            "precision": day.precision.to_dict(),
            "rms_alpha_urad": float(np.sqrt(np.mean(ea**2))),
            "rms_beta_urad": float(np.sqrt(np.mean(eb**2))),
            "worst_urad": float(np.max(np.abs(np.r_[ea, eb]))),
            "run_s": seconds,
        },
        args.rows,
    )


if __name__ == "__main__":
    main()
