"""Clouds with height through the whole assessment: the rendered collocation takes the rows' parallax away.

Whether the day keeps its lift is the cost's decision (:mod:`monitor.estimation.parallax`, its tests); on
three granules the rendered probe's gain is not significant on this case, so the test reads the probe's
collocation itself: the day's estimate at the probe's scale, the case's law within 5 %."""

import numpy as np

from monitor.assessment.assess import collocate_plan, cost_and_offsets
from monitor.collocation.lift import PROBE_M_PER_K
from monitor.config.assessment import AssessmentConfig
from monitor.sdr.pairing import plan


def test_the_rendered_collocation_takes_the_rows_parallax_away(cases):
    out, _, result = cases.get(seed=3, granules=3, clouds="lapse:6.5")
    assert len({f.parallax_m_per_k for f in result.fors}) == 1  # one scale for the day
    cfg = AssessmentConfig(parallax=False)
    case = plan([out])
    raw = cost_and_offsets(collocate_plan(case, cfg), cfg, satellite="j01")  # at their GEO points
    raw_rows = np.array([f.fov_rows_alpha_urad for f in raw.fors])
    assert np.nanmedian(raw_rows) < -120  # the parallax of tops ~8-14 km: the rows ahead turned back
    assert np.all(np.isnan([f.parallax_m_per_k for f in raw.fors]))  # not collocated with a lift
    probe = collocate_plan(case, cfg, lift_m_per_k=PROBE_M_PER_K)
    rows = np.array([f.fov_rows_alpha_urad for f in cost_and_offsets(probe, cfg, satellite="j01").fors])
    # at least half of it gone (the point lift, 028d857: 78 of 228 urad left at the day's own lift)
    assert abs(np.nanmedian(rows)) < 0.5 * abs(np.nanmedian(raw_rows))
