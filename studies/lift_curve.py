"""The day's cost over whole renderings at several lifts, beside the lift the blend prefers at each.

The assessment seeks the day's lift on the blend V0 + f (V1 - V0) of the collocation at no lift (V0) and
the one rendered at the probe's lift (V1, :data:`monitor.collocation.lift.PROBE_M_PER_K`). Here the case
is collocated once per lift of *lifts*, each rendered whole (:mod:`monitor.collocation.render`), and for
each the day's cost (:func:`monitor.estimation.parallax.row_costs`, K, per FOV row: ahead, centre,
behind) is printed at no lift, at that rendering (f = 1), and at the blend's own minimum with that
rendering as its probe (f and the cost there): whether the day's cost over renderings has its least near
the case's law, and how far the blend's preferred lift follows its probe (docs/science.md, "One
rendering at the day's lift"). One JSON row per lift.

    .venv/bin/python -m studies.lift_curve CASE_DIR --lifts 100,150,200,250,300 [--workers 2]
        [--rows FILE]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from benchmarks.provenance import commit, emit
from monitor.assessment.estimates import for_samples, paired
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR
from monitor.estimation import parallax
from monitor.instrument.spectral import i5_band
from monitor.simulate.case import law_m_per_k
from studies.collocated import collocated


def curve(case: Path, lifts_m_per_k: list[float], workers: int) -> list[dict]:
    """The rows of one case (module docstring), one per lift of *lifts_m_per_k*."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig(workers=workers)
    band = i5_band(truth["satellite"])
    rows = []
    for lift in lifts_m_per_k:
        p0, p1 = paired(collocated(case, cfg, workers, lift))
        cones = [
            parallax.matched_cone(for_samples(p0, k, cfg, band), for_samples(p1, k, cfg, band), cfg.cost)
            for k in range(N_FOR)
        ]
        s0, s1 = [a for a, _ in cones], [b for _, b in cones]
        f = parallax.day_fraction(s0, s1, cfg.cost)
        rows.append(
            {
                "commit": commit(),
                "case": case.name,
                "clouds": truth.get("cloud_heights", "ground"),
                "law_m_per_k": law_m_per_k(truth["satellite"], truth.get("cloud_heights", "ground")),
                "fov_rows_alpha_urad": truth.get("fov_rows_alpha_urad", 0.0),
                "lift_m_per_k": lift,
                "cost_unlifted_k": parallax.row_costs(s0, s1, 0.0, cfg.cost).round(4).tolist(),
                "cost_rendered_k": parallax.row_costs(s0, s1, 1.0, cfg.cost).round(4).tolist(),
                "blend_preferred_m_per_k": round(f * lift, 1),
                "cost_blend_k": parallax.row_costs(s0, s1, f, cfg.cost).round(4).tolist(),
                "samples": int(sum(len(a) for a in s0)),
            }
        )
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case", type=Path)
    p.add_argument("--lifts", required=True, help="comma-separated lifts, m/K")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    try:
        lifts = [float(v) for v in args.lifts.split(",")]
    except ValueError:
        p.error(f"--lifts {args.lifts!r}: not comma-separated numbers (m/K)")
    if not lifts or min(lifts) <= 0:
        p.error(f"--lifts {args.lifts!r}: every lift must be above 0 m/K")
    for row in curve(args.case, lifts, args.workers):
        emit(row, args.rows)


if __name__ == "__main__":
    main()
