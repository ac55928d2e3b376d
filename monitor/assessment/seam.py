"""The one seam for studies: what a study may vary in the assessment, said in one place.

The service assesses with :data:`SERVICE`, the defaults. A study that varies the rendering of clouds with
height, the VIIRS pixels as they are prepared, how a FOR's collocations at no lift and at the probe's are
combined, or the probe's lift itself, passes its own :class:`Variation` to
:class:`~monitor.assessment.DayAssessment` (or to :func:`~monitor.assessment.assess.collocate_run` and
:func:`~monitor.assessment.estimates.cost_and_offsets`, which the day composes). No other product
signature carries a switch that only a study sets.
"""

from __future__ import annotations

from dataclasses import dataclass

from monitor.assessment.inputs import PieceVariant
from monitor.collocation import render
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.estimation import parallax


@dataclass(frozen=True)
class Variation:
    """What a study varies; each default is the service's.

    Attributes
    ----------
    renderer : Renderer
        What renders the VIIRS pixels standing at a height as each CrIS FOV row sees them
        (:func:`monitor.collocation.render.rendered_bt`).
    piece : callable or None
        A change to each VIIRS granule as it is prepared (the pixels the cone kernel sees); None: none.
    blend : Blend
        How a FOR's samples at no lift and at the probe's are combined at a fraction of the probe's lift
        (:func:`monitor.estimation.parallax.blend`).
    probe_m_per_k : float
        The lift of the rendered collocation (m per K of I5 BT below the clear sky) from which the day's lift
        is found (:mod:`monitor.estimation.parallax`).
    """

    renderer: render.Renderer = render.rendered_bt
    piece: PieceVariant | None = None
    blend: parallax.Blend = parallax.blend
    probe_m_per_k: float = PROBE_M_PER_K


SERVICE = Variation()
