"""The day's cost over the lift with each row's grid minimum, and with its sub-step minimum.

The day's lift is the fraction f of the probe's where the sum of every FOR's FOV rows' cost minima is least
(:mod:`monitor.estimation.parallax`). Here that sum is computed on a grid of f twice as fine as the
search's, once with each row's minimum taken as the surface's least grid value (``numpy.nanmin``) and once
as the value of the quadratic through its 3 x 3 at the sub-step minimum
(:func:`monitor.estimation.cost.minimum_value`, the service's), for the rendering with each ray at its own
place across the track (the service's) and, with ``--sweep``, for the sweep alone: whether the grid's
minimum shapes the curve, and so the lift, by where the rows' turns lie on the grid
(studies/clouds-with-height.md, section 4). One JSON row per rendering and
minimum: f at the curve's least (refined by the parabola through the least three), the lift in m per K,
the case's law, and the curve less its least, K.

    .venv/bin/python -m studies.row_minimum CASE_DIR... [--sweep] [--workers 2] [--rows FILE]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.estimates import for_samples, paired
from monitor.collocation import render
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR
from monitor.estimation import parallax
from monitor.estimation.cost import minimum_value
from monitor.instrument.spectral import i5_band
from studies.collocated import collocated

FINE = np.linspace(parallax.FRACTIONS[0], parallax.FRACTIONS[-1], 2 * len(parallax.FRACTIONS) - 1)


def grid_minimum(cost_k: np.ndarray) -> float:
    """The surface's least grid value, K."""
    return float(np.nanmin(cost_k))


MINIMA = {"grid": grid_minimum, "sub-step": minimum_value}


def least(curve_k: np.ndarray) -> float:
    """The f of FINE where *curve_k* is least, refined by the parabola through the least three."""
    i = int(np.clip(np.argmin(curve_k), 1, len(FINE) - 2))
    y0, y1, y2 = curve_k[i - 1 : i + 2]
    bend = y0 - 2 * y1 + y2
    shift = float(np.clip(0.5 * (y0 - y2) / bend, -1.0, 1.0)) if bend > 0 else 0.0
    return float(FINE[i] + shift * (FINE[1] - FINE[0]))


def measure(case: Path, workers: int, sweep: bool) -> list[dict]:
    """The rows of one case (module docstring)."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig(workers=workers)
    band = i5_band(truth["satellite"])
    renderings = {"across": render.rendered_bt}
    if sweep:
        renderings["sweep"] = render.swept_bt
    rows = []
    for name, renderer in renderings.items():
        p0, p1 = paired(collocated(case, cfg, workers, PROBE_M_PER_K, renderer=renderer))
        cones = [
            parallax.matched_cone(for_samples(p0, k, cfg, band), for_samples(p1, k, cfg, band), cfg.cost)
            for k in range(N_FOR)
        ]
        s0, s1 = [a for a, _ in cones], [b for _, b in cones]
        for label, minimum in MINIMA.items():
            curve = np.array([parallax.day_cost(s0, s1, float(f), cfg.cost, minimum=minimum) for f in FINE])
            f = least(curve)
            rows.append({
                "commit": commit(), "case": case.name, "clouds": truth.get("cloud_heights"),
                "granules": truth["granules"],
                "fov_rows_alpha_urad": truth.get("fov_rows_alpha_urad", 0.0), "rendering": name,
                "minimum": label, "f": round(f, 3), "lift_m_per_k": round(f * PROBE_M_PER_K, 1),
                "law_m_per_k": truth.get("law_m_per_k"),
                "curve_k": [round(float(c), 3) for c in curve - curve.min()],
            })  # fmt: skip
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", type=Path)
    p.add_argument("--sweep", action="store_true", help="also the sweep alone (render.swept_bt)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    for case in args.cases:
        for row in measure(case, args.workers, args.sweep):
            emit(row, args.rows)


if __name__ == "__main__":
    main()
