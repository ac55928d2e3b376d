"""The parallax correction's alternatives on simulated cases: no lift, an assumed lift (the probe's 180 m/K,
6.5 K/km seen through the window channel), the lift the day's cost chooses (the default), and that lift with
each FOR's high clouds left out (``--leave-out-above-km``: the samples the learnt lift puts higher than
that above the FOR's warm scenes, its 95th percentile of CrIS BT; none on a day whose lift is declined).
For each: the FOR offsets' RMS and worst error per direction, and the rows' (ahead minus behind) median
error against the truth. The two collocations (none, the probe's) are made once per case, in one pass.
Prints one JSON row per case and alternative.

    .venv/bin/python -m studies.parallax_alternatives CASE_DIR... [--leave-out-above-km 8 5 3]
                                                         [--workers 2] [--rows FILE]

A case directory is one ``crisgeo simulate`` (or ``benchmarks.acceptance --keep``) wrote, with truth.json.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.estimates import cost_and_offsets, paired
from monitor.assessment.seam import Variation
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.config.assessment import AssessmentConfig
from monitor.core.result import AssessmentResult
from monitor.estimation import parallax
from monitor.estimation.estimate import ForSamples
from studies.collocated import collocated


def errors(result: AssessmentResult, truth: dict) -> dict:
    """RMS and worst FOR error per direction, and the rows' median error, against *truth* (urad)."""
    ta = np.array([f["d_alpha_urad"] for f in truth["fors"]])
    tb = np.array([f["d_beta_urad"] for f in truth["fors"]])
    ea = np.array([f.d_alpha_urad for f in result.fors]) - ta
    eb = np.array([f.d_beta_urad for f in result.fors]) - tb
    rows = np.array([f.fov_rows_alpha_urad for f in result.fors]) - truth.get("fov_rows_alpha_urad", 0.0)
    return {
        "rms_alpha_urad": round(float(np.sqrt(np.nanmean(ea**2))), 1),
        "rms_beta_urad": round(float(np.sqrt(np.nanmean(eb**2))), 1),
        "worst_alpha_urad": round(float(np.nanmax(np.abs(ea))), 1),
        "worst_beta_urad": round(float(np.nanmax(np.abs(eb))), 1),
        "rows_median_error_urad": round(float(np.nanmedian(rows)), 1),
        "m_per_k": round(float(result.fors[0].parallax_m_per_k), 1),
    }


def without_high_clouds(above_km: float) -> Callable[[ForSamples, ForSamples, float], ForSamples]:
    """:func:`monitor.estimation.parallax.blend` with the samples the lift at *f* puts more than *above_km*
    above the FOR's warm scenes (95th percentile of its CrIS BT) left out (all kept at f = 0)."""
    blend = parallax.blend

    def blended(s0: ForSamples, s1: ForSamples, f: float) -> ForSamples:
        s = blend(s0, s1, f)
        if f <= 0 or len(s) < 3:
            return s
        keep = s.cris_k >= np.percentile(s.cris_k, 95) - above_km * 1e3 / (f * PROBE_M_PER_K)
        some = [None if a is None else a[keep] for a in (s.annuli_rad, s.fov)]
        return replace(
            s, d_k=s.d_k[keep], cris_k=s.cris_k[keep], granule=s.granule[keep], scan=s.scan[keep],
            annuli_rad=some[0], fov=some[1],
        )  # fmt: skip

    return blended


def alternatives(case: Path, leave_out_above_km: list[float], workers: int) -> list[dict]:
    """The rows of one case: none, assumed, learnt, and learnt without the clouds above each height."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig(workers=workers)
    sat = truth["satellite"]
    both = collocated(case, cfg, workers, PROBE_M_PER_K)
    ground = [replace(s, rendered=None) for s in both]
    pairs = paired(both)
    base = {"commit": commit(), "case": case.name, "clouds": truth.get("cloud_heights", "ground")}
    rows = [
        {**base, "alternative": "none", **errors(cost_and_offsets(ground, cfg, satellite=sat), truth)},
        {**base, "alternative": "assumed", **errors(cost_and_offsets(pairs[1], cfg, satellite=sat), truth)},
        {
            **base,
            "alternative": "learnt",
            **errors(cost_and_offsets(both, cfg, satellite=sat), truth),
        },
    ]
    rows[1]["m_per_k"] = PROBE_M_PER_K
    for above_km in leave_out_above_km:
        # the assessment blends each FOR through the seam's blend: the samples are thinned there
        variation = Variation(blend=without_high_clouds(above_km))
        result = cost_and_offsets(both, cfg, satellite=sat, variation=variation)
        rows.append(
            {**base, "alternative": f"learnt, clouds above {above_km:g} km left out", **errors(result, truth)}
        )
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", type=Path)
    p.add_argument("--leave-out-above-km", nargs="*", type=float, default=[])
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    for case in args.cases:
        for row in alternatives(case, args.leave_out_above_km, args.workers):
            emit(row, args.rows)


if __name__ == "__main__":
    main()
