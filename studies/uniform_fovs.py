"""How many FOVs of a day see a uniform scene: the share whose turned cones could be skipped (issue 37's
lever). For each usable FOV of each CrIS granule of a case, the range (max - min) of its VIIRS BT over the
21 x 21 turned cones; a FOV whose range is below a threshold adds almost nothing to a cost's curvature.
Prints, per granule and for the whole case, the quantiles of that range and the share of FOVs below each
threshold; and the floor that skipping them would leave (the share of the collocation's work that remains).

    .venv/bin/python -m studies.uniform_fovs DIR [--granules N]      (DIR: a simulated case)

DIR is e.g. the bench case (``crisgeo bench --granules 14 --data DIR``). Figures of 2026-11-25 in
docs/performance.md.
"""

from __future__ import annotations

import argparse

import numpy as np

from monitor.assessment.assess import collocate_run
from monitor.config.assessment import AssessmentConfig
from monitor.sdr.pairing import plan

THRESHOLDS_K = (0.2, 0.5, 1.0, 2.0)


def main() -> None:
    """Collocate the case's granules with the default assessment and print the uniform shares."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data")
    p.add_argument("--granules", type=int, default=0, help="the first N granules only (0: all)")
    args = p.parse_args()
    case = plan([args.data])
    cris = case.cris[: args.granules] if args.granules else case.cris
    samples, _ = collocate_run(cris, case.viirs, case.viirs_all, case.satellite, AssessmentConfig())
    ranges = []
    for s in samples:
        bt = s.bt_viirs_k[s.usable]
        r = np.nanmax(bt, axis=(1, 2)) - np.nanmin(bt, axis=(1, 2))
        ranges.append(r)
        shares = ", ".join(f"< {t:g} K: {np.mean(r < t):.2f}" for t in THRESHOLDS_K)
        print(f"{s.key}: {len(r)} FOVs, range median {np.median(r):.2f} K; {shares}")
    r = np.concatenate(ranges)
    q = np.quantile(r, [0.1, 0.25, 0.5, 0.75, 0.9])
    print(f"all {len(r)} FOVs: range quantiles 10/25/50/75/90 %: {', '.join(f'{v:.2f}' for v in q)} K")
    for t in THRESHOLDS_K:
        print(
            f"  uniform below {t:g} K: {np.mean(r < t):.1%} of the FOVs (the kernel's work left: about "
            f"{1 - np.mean(r < t):.0%})"
        )


if __name__ == "__main__":
    main()
