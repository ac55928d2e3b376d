"""CrIS-VIIRS calibration differences against the two costs: the geolocation error of each.

Simulates cases (paper profile) whose CrIS BT departs from VIIRS's by a bias, a gain about 280 K and a
curvature (:class:`monitor.simulate.case.SimulationSpec`), assesses each with ``stdev`` (the paper's
equation 8) and ``regression`` (docs/science.md), and prints the RMS error in-track / cross-track and the
worst FOR (urad) over the reliable FORs.

    PYTHONPATH=. .venv/bin/python studies/mismatch.py [--granules 6] [--seeds 1 2]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from monitor.assessment.assess import assess_paths
from monitor.config.assessment import AssessmentConfig
from monitor.core.result import AssessmentResult
from monitor.core.vocabulary import Cost, Kernel
from monitor.simulate.case import simulate_case

# (gain, bias K, curvature K): none, the gains, the paper's profile, curvatures of 0.5 K
DIFFERENCES = [(0.0, 0.0, 0.0), (0.03, 0.0, 0.0), (-0.03, 1.5, 0.0), (0.01, 0.0, 0.5), (0.0, 2.0, -0.5)]


def truth_arrays(truth: dict) -> tuple[np.ndarray, np.ndarray]:
    """The case's true offsets (urad), in-track and cross-track, per FOR."""
    return (
        np.array([f["d_alpha_urad"] for f in truth["fors"]]),
        np.array([f["d_beta_urad"] for f in truth["fors"]]),
    )


def errors(result: AssessmentResult, truth: dict) -> str:
    """RMS in-track / cross-track and worst FOR (urad) over the reliable FORs."""
    ta, tb = truth_arrays(truth)
    ok = np.array([f.reliable for f in result.fors])
    ea = np.array([f.d_alpha_urad for f in result.fors])[ok] - ta[ok]
    eb = np.array([f.d_beta_urad for f in result.fors])[ok] - tb[ok]
    worst = max(np.abs(ea).max(), np.abs(eb).max())
    return f"{np.sqrt(np.mean(ea**2)):.1f}/{np.sqrt(np.mean(eb**2)):.1f}, {worst:.0f} ({ok.sum()} FORs)"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("--granules", type=int, default=6)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args(argv)
    print("| seed | gain | bias K | curvature K | stdev | regression |")
    for seed in args.seeds:
        for gain, bias_k, curve_k in DIFFERENCES:
            out = Path(tempfile.mkdtemp(prefix="crisgeo-mismatch-"))
            truth = simulate_case(
                out, granules=args.granules, profile="paper", seed=seed,
                cris_gain=gain, cris_bias_k=bias_k, cris_nonlinear_k=curve_k,
            )  # fmt: skip
            cells = [
                errors(assess_paths([out], AssessmentConfig(kernel=Kernel.TOP_HAT, cost=cost)), truth)
                for cost in Cost
            ]
            print(f"| {seed} | {gain:+.2f} | {bias_k} | {curve_k} | {' | '.join(cells)} |", flush=True)


if __name__ == "__main__":
    main()
