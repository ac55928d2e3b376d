"""Acceptance on CrIS spatial responses the code was never given; 6 granules each, the default assessment.

``--set within``: four radially symmetric shapes within the specification's table that are not among
:data:`monitor.instrument.footprint.SHAPES` (a sharper and a softer super-Gaussian, a steep trapezoid, a
narrower blur), on seeds 4-7 that no other acceptance run uses.

``--set stretched``: an instrument out of its table, which the product exists to notice: shapes 5 % wider and
5 % narrower at every level, and elliptical ones, their axes a few per cent apart at an angle drawn from the
case's seed (and turned by each FOR's scan angle), on seeds 31-36 that no choice was made on.

Prints one JSON row per case: RMS per direction and the worst FOR (urad), the share of errors within two
sigmas, the median intercalibration (gain per cent, bias K) where none was injected, the median fitted full
width at half peak against the truth's (urad; an elliptical response's is its azimuthal mean's), and what the
specification check says of the truth.

    .venv/bin/python -m benchmarks.unseen_shapes --set within > rows.jsonl      (~6 min on two cores)

Rows: ``studies/rows/acceptance_unseen_shapes_2026-11-25.jsonl`` (within),
``acceptance_stretched_shapes_2026-11-26.jsonl`` (stretched).
"""

from __future__ import annotations

import argparse
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


def _elliptical(base: str, a: float, b: float, seed: int) -> footprint.Response:
    """*base* stretched *a* and *b* times along axes at an angle drawn from *seed*, not chosen."""
    angle_deg = float(np.random.default_rng(seed).uniform(0.0, 180.0))
    return footprint.shape(f"{base}:{a}x{b}@{angle_deg:.1f}")


WITHIN = (  # (name, response, seed, profile, ground)
    ("super-gaussian order 16", footprint.super_gaussian(order=16.0), 4, "paper", "flat"),
    ("trapezoid 0.442-0.500 deg", footprint.trapezoid(math.radians(0.442), math.radians(0.5)), 5, "random",
     "terrain"),
    ("super-gaussian order 9", footprint.super_gaussian(order=9.0), 6, "random", "flat"),
    ("blurred 0.471 deg, sigma 0.03", footprint.blurred_top_hat(math.radians(0.471), math.radians(0.03)), 7,
     "paper", "terrain"),
)  # fmt: skip
STRETCHED = (
    ("trapezoid 5 % narrower", footprint.shape("trapezoid:0.95"), 31, "random", "flat"),
    ("super-gaussian order 12, 5 % wider", footprint.super_gaussian(order=12.0).stretched(1.05), 32, "paper",
     "terrain"),
    ("blurred 5 % wider", footprint.shape("blurred:1.05"), 33, "random", "terrain"),
    ("super-gaussian order 8, 5 % narrower", footprint.super_gaussian(order=8.0).stretched(0.95), 34, "paper",
     "flat"),
    ("trapezoid 1.5 % x -1.5 %", _elliptical("trapezoid", 1.015, 0.985, 35), 35, "random", "flat"),
    ("blurred 2 % x -1 %", _elliptical("blurred", 1.02, 0.99, 36), 36, "paper", "terrain"),
)  # fmt: skip
SETS = {"within": WITHIN, "stretched": STRETCHED}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--set", choices=tuple(SETS), default="within")
    parser.add_argument("--only", help="the cases whose name holds this")
    args = parser.parse_args()
    for name, response, seed, profile, ground in SETS[args.set]:
        if args.only and args.only not in name:
            continue
        if args.set == "within":
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
            "spec_check": response.within_spec(),
            "parallax_m_per_k": result.fors[0].parallax_m_per_k,
        }
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
