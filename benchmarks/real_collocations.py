"""The estimator on the only real radiances within reach: the reference implementation's collocations of ten
NOAA-20 granules (tests/data/real/collocations_j01_20181022, README there).

Prints
- the day's offsets, jackknife sigmas and cost minimum per FOR (``crisgeo assess FILE.npz`` does the same);
- the honesty of the sigmas: over random splits of the granules into halves, the share of FOR-directions
  whose halves differ by more than 2 combined sigmas (honest: ~5 %, and up to ~12 % with so few granules
  per half: the sigmas themselves are estimated from 5) and the rms of the normalised difference (honest: 1);
- the intercalibration: the product's per FOR (on the scenes the collocation cannot move), against least
  squares over every sample pooled (what reads the collocation as calibration);
- what N consecutive real granules resolve: the median per-FOR sigma for N = 4..10.

    .venv/bin/python -m benchmarks.real_collocations [--splits 20] [--seed 42]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from monitor.assessment.replay import assess_collocations, for_samples, read_collocation
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import CALIBRATION_REFERENCE_K, N_FOR
from monitor.core.result import AssessmentResult
from monitor.core.vocabulary import Kernel
from monitor.estimation.estimate import estimate

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "real" / "collocations_j01_20181022"


def splits(files: list[Path], cfg: AssessmentConfig, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Normalised differences of the halves' offsets over *n* random splits (FOR-directions, NaN kept), and
    per split the difference of the halves' median biases (K: what a change of scenes alone does to the
    series calibration_jump watches)."""
    rng = np.random.default_rng(seed)
    z: list[float] = []
    apart_k: list[float] = []
    for _ in range(n):
        p = rng.permutation(len(files))
        half = len(files) // 2
        a, b = (assess_collocations([files[i] for i in idx], cfg).fors for idx in (p[:half], p[half:]))
        apart_k.append(np.nanmedian([f.bias_k for f in a]) - np.nanmedian([f.bias_k for f in b]))
        for fa, fb in zip(a, b, strict=True):
            z.append((fa.d_alpha_urad - fb.d_alpha_urad) / np.hypot(fa.sigma_alpha_urad, fb.sigma_alpha_urad))
            z.append((fa.d_beta_urad - fb.d_beta_urad) / np.hypot(fa.sigma_beta_urad, fb.sigma_beta_urad))
    return np.array(z), np.array(apart_k)


def intercalibration(day: AssessmentResult, files: list[Path], cfg: AssessmentConfig) -> list[str]:
    """The product's intercalibration (monitor/estimation/intercal.py) against an ordinary least-squares
    fit of C - V on V over every sample at each FOR's optimum, pooled (what the product did until
    2026-11-26)."""
    granules = [read_collocation(f) for f in files]
    cs, vs = [], []
    for k in range(N_FOR):
        s = for_samples(granules, k)
        e = estimate(s, cfg.cost, cfg.flat_contrast, uncertainty=False)
        cs.append(s.cris_k)
        vs.append(e.d_opt + s.cris_k)
    c, v = np.concatenate(cs), np.concatenate(vs)
    gain, bias = np.polyfit(v - CALIBRATION_REFERENCE_K, c - v, 1)
    bias_k = np.array([f.bias_k for f in day.fors])
    determined = [f for f in day.fors if np.isfinite(f.gain_pct)]
    return [
        f"least squares on every sample, pooled: gain {100 * gain:+.2f} %, bias {bias:+.3f} K at 280 K",
        f"the product: gain determined at {len(determined)}/{len(day.fors)} FORs"
        + (f" (median {np.median([f.gain_pct for f in determined]):+.2f} %)" if determined else "")
        + f", bias median {np.nanmedian(bias_k):+.3f} K"
        + f" (FORs {np.nanmin(bias_k):+.3f}..{np.nanmax(bias_k):+.3f}),"
        f" median sigma {np.nanmedian([f.sigma_bias_k for f in day.fors]):.3f} K",
    ]


def resolution(files: list[Path], cfg: AssessmentConfig) -> list[str]:
    """What N consecutive real granules resolve: the median per-FOR sigma over every window of N."""
    out = [f"{'granules':>8} {'windows':>7} {'sigma in-track':>15} {'sigma cross-track':>18}  (urad, median)"]
    for n in range(4, len(files) + 1):
        sig = []
        for start in range(len(files) - n + 1):
            fors = assess_collocations(files[start : start + n], cfg).fors
            sig.append(
                [
                    np.nanmedian([f.sigma_alpha_urad for f in fors]),
                    np.nanmedian([f.sigma_beta_urad for f in fors]),
                ]
            )
        s = np.median(sig, axis=0)
        out.append(f"{n:>8} {len(sig):>7} {s[0]:15.0f} {s[1]:18.0f}")
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--splits", type=int, default=20)
    p.add_argument("--seed", type=int, default=42)
    args = p.parse_args()
    files = sorted(DATA.glob("*.npz"))
    cfg = AssessmentConfig(kernel=Kernel.TOP_HAT)  # the files hold cone means
    day = assess_collocations(files, cfg, "j01")
    print("\n".join(day.notes))
    print(f"{'FOR':>3} {'d_alpha':>8} {'+-':>5} {'d_beta':>8} {'+-':>5} {'G_min K':>8}  flags")
    for f in day.fors:
        print(
            f"{f.for_index:>3} {f.d_alpha_urad:8.0f} {f.sigma_alpha_urad:5.0f} {f.d_beta_urad:8.0f} "
            f"{f.sigma_beta_urad:5.0f} {f.cost_min_k:8.3f}  {','.join(f.flags)}"
        )
    z, apart_k = splits(files, cfg, args.splits, args.seed)
    ok = z[np.isfinite(z)]
    print(
        f"split halves ({args.splits} splits, {ok.size} FOR-directions): "
        f"{100 * np.mean(np.abs(ok) > 2):.1f} % beyond 2 combined sigmas, rms normalised difference "
        f"{np.sqrt(np.mean(ok**2)):.2f}; the halves' median biases at most "
        f"{np.max(np.abs(apart_k)):.3f} K apart"
    )
    print("\n".join(intercalibration(day, files, cfg)))
    print("\n".join(resolution(files, cfg)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
