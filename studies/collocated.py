"""A case's collocated samples, for a study that estimates them otherwise than the assessment does.

The assessment collocates a day batch by batch (:class:`monitor.assessment.DayAssessment`); a study takes
its samples from the same class, with the probe's lift, the renderer and the prepared pieces it varies passed
through the assessment's one seam for studies (:class:`monitor.assessment.seam.Variation`).
"""

from __future__ import annotations

import json
from pathlib import Path

from monitor.assessment import DayAssessment
from monitor.assessment.estimates import GranuleSamples
from monitor.assessment.inputs import PieceVariant
from monitor.assessment.seam import Variation
from monitor.collocation import render
from monitor.config.assessment import AssessmentConfig
from monitor.sdr.pairing import plan

_DAYS: list[DayAssessment] = []  # kept open (their spooled samples on disk) until the process ends


def collocated(
    case: Path,
    cfg: AssessmentConfig | None = None,
    workers: int = 1,
    lift_m_per_k: float = 0.0,
    renderer: render.Renderer = render.rendered_bt,
    piece_variant: PieceVariant | None = None,
) -> list[GranuleSamples]:
    """The samples of every CrIS granule of the simulated *case* (a directory with ``truth.json``), in time
    order, with their collocation rendered at *lift_m_per_k* m per K by *renderer* when it is not 0, and
    each VIIRS granule changed by *piece_variant* as it is prepared."""
    cfg = (cfg or AssessmentConfig()).model_copy(update={"parallax": bool(lift_m_per_k)})
    satellite = json.loads((case / "truth.json").read_text())["satellite"]
    probe = lift_m_per_k or 1.0
    variation = Variation(renderer=renderer, piece=piece_variant, probe_m_per_k=probe)
    day = DayAssessment(satellite, cfg, workers, variation)
    _DAYS.append(day)
    day.add(plan([case]))
    return day.samples
