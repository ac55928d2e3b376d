"""The estimator on the only real radiances within reach: the reference implementation's collocations of ten
NOAA-20 granules (tests/data/real/collocations_j01_20181022, README there).

Prints
- the day's offsets, jackknife sigmas and cost minimum per FOR (``crisgeo assess FILE.npz`` does the same);
- the honesty of the sigmas: over random splits of the granules into halves, the share of FOR-directions
  whose halves differ by more than 2 combined sigmas (honest: ~5 %, and up to ~12 % with so few granules
  per half: the sigmas themselves are estimated from 5) and the rms of the normalised difference (honest: 1);
- the intercalibration at the optimum, pooled over all FORs: on every sample, and on the samples whose cone
  mean varies by less than a threshold over +-3 turn steps about the optimum (uniform scenes, where the
  collocation cannot matter; GSICS practice), with the 5-95 % range of their BT.

    .venv/bin/python -m benchmarks.real_collocations [--splits 20] [--seed 42]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from monitor.assessment.replay import assess_collocations, for_samples, read_collocation
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR
from monitor.core.vocabulary import Kernel
from monitor.estimation import refine
from monitor.estimation.estimate import estimate
from monitor.estimation.intercal import fit_difference

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "real" / "collocations_j01_20181022"
UNIFORM_K = (1.0, 0.5, 0.3)  # spread of the cone mean over +-3 turn steps (K) below which a scene is uniform


def splits(files, cfg, n: int, seed: int) -> np.ndarray:
    """Normalised differences of the halves' offsets over *n* random splits (FOR-directions, NaN kept)."""
    rng = np.random.default_rng(seed)
    z = []
    for _ in range(n):
        p = rng.permutation(len(files))
        half = len(files) // 2
        a, b = (assess_collocations([files[i] for i in idx], cfg).fors for idx in (p[:half], p[half:]))
        for fa, fb in zip(a, b, strict=True):
            for axis in ("alpha", "beta"):
                diff = getattr(fa, f"d_{axis}_urad") - getattr(fb, f"d_{axis}_urad")
                z.append(
                    diff / np.hypot(getattr(fa, f"sigma_{axis}_urad"), getattr(fb, f"sigma_{axis}_urad"))
                )
    return np.array(z)


def uniform_intercalibration(files, cfg) -> list[str]:
    """The pooled intercalibration on every sample and on the uniform ones."""
    granules = [read_collocation(f) for f in files]
    c, v, spread = [], [], []
    for k in range(N_FOR):
        s = for_samples(granules, k)
        e = estimate(s, cfg.cost, cfg.flat_contrast, uncertainty=False)
        i0, j0 = e.cost.shape[0] // 2 + round(e.x), e.cost.shape[1] // 2 + round(e.y)
        h = refine.HALF
        win = s.d_k[:, max(i0 - h, 0) : i0 + h + 1, max(j0 - h, 0) : j0 + h + 1] + s.cris_k[:, None, None]
        c.append(s.cris_k)
        v.append(e.d_opt + s.cris_k)
        spread.append(win.max(axis=(1, 2)) - win.min(axis=(1, 2)))
    c, v, spread = (np.concatenate(x) for x in (c, v, spread))
    out = [f"{'samples':<24} {'share':>6} {'bias K':>7} {'gain %':>7} {'curv K':>7}  BT 5-95 %"]
    for name, sel in [("all", np.ones(c.size, bool))] + [
        (f"cone mean spread < {t:g} K", spread < t) for t in UNIFORM_K
    ]:
        b, g, cv = fit_difference(c[sel], v[sel])
        lo, hi = np.percentile(v[sel], [5, 95])
        out.append(f"{name:<24} {sel.mean():6.2f} {b:+7.3f} {100 * g:+7.2f} {cv:+7.3f}  {lo:.1f}-{hi:.1f} K")
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
    z = splits(files, cfg, args.splits, args.seed)
    ok = z[np.isfinite(z)]
    print(
        f"split halves ({args.splits} splits, {ok.size} FOR-directions): "
        f"{100 * np.mean(np.abs(ok) > 2):.1f} % beyond 2 combined sigmas, rms normalised difference "
        f"{np.sqrt(np.mean(ok**2)):.2f}"
    )
    print("\n".join(uniform_intercalibration(files, cfg)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
