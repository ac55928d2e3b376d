"""The FOV rows' signature on the real collocations: per FOR, the offset estimated from the rows ahead
(FOVs 7-9) alone minus that from the rows behind (FOVs 1-3) alone, with the paper's STDEV cost on the
reference implementation's cone means, grid minimum and quadratic refinement (the fact sheet's method), and
with the assessment's own estimator (``fov_rows_*``, regression cost); and how far the FOR offsets of one
granule alone scatter from granule to granule (the median over FORs of their standard deviation). Prints
one JSON row.

    .venv/bin/python -m benchmarks.fov_rows [FILES.npz ...]     (default: the ten in tests/data/real)
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit
from monitor.assessment.replay import assess_collocations, read_collocation
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR, URAD
from monitor.estimation.estimate import FOV_ROWS, find_minimum

REAL = sorted((Path(__file__).parent.parent / "tests/data/real/collocations_j01_20181022").glob("*.npz"))


def stdev_rows(paths: list[Path]) -> np.ndarray:
    """(N_FOR, 2) ahead minus behind (urad, in-track and cross-track) by the paper's STDEV cost."""
    granules = [read_collocation(p) for p in paths]
    step_urad = granules[0].step_rad / URAD
    out = np.empty((N_FOR, 2))
    for k in range(N_FOR):
        xy = []
        for fovs in FOV_ROWS:
            d = np.concatenate(
                [
                    (g.v_bt_k[:, k][:, fovs] - g.c_bt_k[:, k][:, fovs][..., None, None])[
                        g.usable[:, k][:, fovs]
                    ]
                    for g in granules
                ]
            )
            x, y, _ = find_minimum(d.std(axis=0))
            xy.append((x, y))
        out[k] = np.subtract(xy[0], xy[1]) * step_urad
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("files", nargs="*", type=Path, default=REAL)
    args = p.parse_args()
    paper = stdev_rows(args.files)
    fors = assess_collocations(args.files, AssessmentConfig()).fors
    own = np.array([[f.fov_rows_alpha_urad, f.fov_rows_beta_urad] for f in fors])
    sigma = np.array([[f.sigma_fov_rows_alpha_urad, f.sigma_fov_rows_beta_urad] for f in fors])
    alone = np.array(
        [
            [[f.d_alpha_urad, f.d_beta_urad] for f in assess_collocations([p], AssessmentConfig()).fors]
            for p in args.files
        ]
    )  # (granules, N_FOR, 2)
    scatter = np.nanmedian(np.nanstd(alone, axis=0, ddof=1), axis=0)
    row = {
        "commit": commit(),
        "granules": len(args.files),
        "stdev_in_track_mean_urad": round(float(paper[:, 0].mean()), 1),
        "stdev_in_track_sem_urad": round(float(paper[:, 0].std(ddof=1) / np.sqrt(N_FOR)), 1),
        "stdev_in_track_negative_fors": int((paper[:, 0] < 0).sum()),
        "stdev_cross_track_mean_urad": round(float(paper[:, 1].mean()), 1),
        "own_in_track_mean_urad": round(float(np.nanmean(own[:, 0])), 1),
        "own_in_track_negative_fors": int((own[:, 0] < 0).sum()),
        "own_cross_track_mean_urad": round(float(np.nanmean(own[:, 1])), 1),
        "own_median_sigma_urad": round(float(np.nanmedian(sigma)), 1),
        "per_granule_scatter_in_track_urad": round(float(scatter[0]), 1),
        "per_granule_scatter_cross_track_urad": round(float(scatter[1]), 1),
    }
    print(json.dumps(row))


if __name__ == "__main__":
    main()
