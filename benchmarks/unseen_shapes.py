"""Acceptance on CrIS spatial responses the code was never given: four radially symmetric shapes within
the specification's table that are not among :data:`monitor.instrument.footprint.SHAPES` (a sharper and a
softer super-Gaussian, a steep trapezoid, a narrower blur), on seeds 4-7 that no other acceptance run uses; 6
granules each, the default assessment. Prints one JSON row per case: RMS per direction and the worst FOR
(urad), the share of errors within two sigmas, the median intercalibration (gain per cent, bias K) where
none was injected, and the median fitted full width at half peak against the truth's (urad).

    .venv/bin/python -m benchmarks.unseen_shapes > rows.jsonl      (~6 min on two cores)

Rows of 2026-11-25: ``benchmarks/results/acceptance_unseen_shapes_2026-11-25.jsonl``.
"""

from __future__ import annotations

import json
import math
import shutil
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit
from monitor.assessment.assess import assess_paths
from monitor.config.assessment import AssessmentConfig
from monitor.instrument import footprint
from monitor.simulate.case import simulate_case

CASES = (  # (name, response, seed, profile, ground)
    ("super-gaussian order 16", footprint.super_gaussian(order=16.0), 4, "paper", "flat"),
    ("trapezoid 0.442-0.500 deg", footprint.trapezoid(math.radians(0.442), math.radians(0.5)), 5, "random",
     "terrain"),
    ("super-gaussian order 9", footprint.super_gaussian(order=9.0), 6, "random", "flat"),
    ("blurred 0.471 deg, sigma 0.03", footprint.blurred_top_hat(math.radians(0.471), math.radians(0.03)), 7,
     "paper", "terrain"),
)  # fmt: skip


def main() -> None:
    for name, response, seed, profile, ground in CASES:
        assert not response.within_spec(), (name, response.within_spec())
        case = Path(tempfile.mkdtemp(prefix="crisgeo-unseen-"))
        try:
            truth = simulate_case(
                case,
                granules=6,
                profile=profile,
                seed=seed,
                terrain=ground == "terrain",
                cris_response=response,
            )
            result = assess_paths([case], AssessmentConfig(), workers=2)
        finally:
            shutil.rmtree(case)
        err_a = np.array([f.d_alpha_urad for f in result.fors]) - [t["d_alpha_urad"] for t in truth["fors"]]
        err_b = np.array([f.d_beta_urad for f in result.fors]) - [t["d_beta_urad"] for t in truth["fors"]]
        sig_a = np.array([f.sigma_alpha_urad for f in result.fors])
        sig_b = np.array([f.sigma_beta_urad for f in result.fors])
        row = {
            "commit": commit(),
            "shape": name,
            "seed": seed,
            "profile": profile,
            "ground": ground,
            "rms_a": float(np.sqrt(np.mean(err_a**2))),
            "rms_b": float(np.sqrt(np.mean(err_b**2))),
            "worst": float(max(np.abs(err_a).max(), np.abs(err_b).max())),
            "cover2": float(np.mean(np.r_[np.abs(err_a) <= 2 * sig_a, np.abs(err_b) <= 2 * sig_b])),
            "gain_pct": float(np.median([f.gain_pct for f in result.fors])),
            "bias_k": float(np.median([f.bias_k for f in result.fors])),
            "fwhm_urad": float(np.nanmedian([f.response_width_50_urad for f in result.fors])),
            "true_fwhm_urad": response.full_width_rad(0.5) / 1e-6,
        }
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
