"""The parallax correction's alternatives on simulated cases: no lift, an assumed lift (the probe's 180 m/K,
6.5 K/km seen through the window channel), and the lift the day's cost chooses (the default). For each:
the FOR offsets' RMS and worst error per direction, and the rows' (ahead minus behind) median error
against the truth. The two collocations (none, the probe's) are made once per case. Prints one JSON row per
case and alternative.

    .venv/bin/python -m benchmarks.parallax_alternatives CASE_DIR... [--rows FILE]

A case directory is one ``crisgeo simulate`` (or ``benchmarks.acceptance --keep``) wrote, with truth.json.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.assess import collocate_plan, cost_and_offsets, paired
from monitor.collocation.parallax import PROBE_M_PER_K
from monitor.config.assessment import AssessmentConfig
from monitor.core.result import AssessmentResult
from monitor.sdr.pairing import plan


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


def alternatives(case: Path) -> list[dict]:
    """The rows of one case: none, assumed, learnt."""
    truth = json.loads((case / "truth.json").read_text())
    cfg = AssessmentConfig()
    sat = truth["satellite"]
    ground = collocate_plan(plan([case]), cfg, workers=2)
    probe = collocate_plan(plan([case]), cfg, workers=2, lift_m_per_k=PROBE_M_PER_K)
    pairs = paired(ground, probe)
    assert pairs is not None
    base = {"commit": commit(), "case": case.name, "clouds": truth.get("cloud_heights", "ground")}
    rows = [
        {**base, "alternative": "none", **errors(cost_and_offsets(ground, cfg, satellite=sat), truth)},
        {**base, "alternative": "assumed", **errors(cost_and_offsets(pairs[1], cfg, satellite=sat), truth)},
        {
            **base,
            "alternative": "learnt",
            **errors(cost_and_offsets(ground, cfg, satellite=sat, probe=probe), truth),
        },
    ]
    rows[1]["m_per_k"] = PROBE_M_PER_K
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("cases", nargs="+", type=Path)
    p.add_argument("--rows", help="append the JSON rows to this file")
    args = p.parse_args()
    for case in args.cases:
        for row in alternatives(case):
            emit(row, args.rows)


if __name__ == "__main__":
    main()
