"""Clouds with height through the whole assessment: the rendered collocation takes the rows' parallax away.

Whether the day keeps its lift is the cost's decision (:mod:`monitor.estimation.parallax`, its tests), made
on three granules from a gain of a sigma or two; so the test renders the pixels at the case's law itself (its
6.5 K/km seen through the window, not the assessment's probe) and reads that collocation; the day's
decision on the same samples is read for its wiring only (one scale for the day)."""

from dataclasses import replace

import numpy as np
import pytest

from monitor.assessment.assess import DayAssessment
from monitor.assessment.estimates import cost_and_offsets
from monitor.assessment.seam import Variation
from monitor.config.assessment import AssessmentConfig
from monitor.sdr.pairing import plan
from monitor.simulate.case import simulate_case

LAW_M_PER_K = 180.0  # 1000 / 6.5 K/km through a window transmittance ~0.85


def _rows_urad(result):
    return np.array([f.fov_rows_alpha_urad for f in result.fors])


@pytest.mark.slow
def test_the_rendered_collocation_takes_the_rows_parallax_away(tmp_path):
    simulate_case(tmp_path, granules=3, profile="paper", seed=3, cloud_heights="lapse:6.5")
    with DayAssessment("j01", variation=Variation(probe_m_per_k=LAW_M_PER_K)) as both:  # in one pass
        both.add(plan([tmp_path]))
        samples = both.samples
    _check_wiring(samples)
    at_geo = [replace(s, rendered=None) for s in samples]
    raw_rows = _rows_urad(cost_and_offsets(at_geo, AssessmentConfig(parallax=False), satellite="j01"))
    assert np.nanmedian(raw_rows) < -120  # the parallax of tops ~8-14 km: the rows ahead turned back
    rows = _rows_urad(
        cost_and_offsets([s.rendered for s in samples], AssessmentConfig(parallax=False), satellite="j01")
    )
    # at least half of it gone
    assert abs(np.nanmedian(rows)) < 0.5 * abs(np.nanmedian(raw_rows))


def test_both_collocations_come_from_one_pass_and_the_unrendered_one_is_the_plain_assessment(cases):
    """The wiring of the rendered collocation on the flat default case (the science is the slow test
    above, on clouds with height): every sample carries its rendered twin and the day takes one scale;
    without the parallax correction nothing is rendered, and the day is the one at the GEO points."""
    out, _, _ = cases.get()
    with DayAssessment("j01", variation=Variation(probe_m_per_k=LAW_M_PER_K)) as both:
        both.add(plan([out]))
        _check_wiring(both.samples)
        cfg = AssessmentConfig(parallax=False)
        at_geo = cost_and_offsets([replace(s, rendered=None) for s in both.samples], cfg, satellite="j01")
    with DayAssessment("j01", cfg) as plain:
        plain.add(plan([out]))
        assert all(s.rendered is None for s in plain.samples)
        raw = plain.result()
    assert np.all(np.isnan([f.parallax_m_per_k for f in raw.fors]))
    assert [f.to_dict() for f in raw.fors] == [f.to_dict() for f in at_geo.fors]


def _check_wiring(samples):
    assert all(s.rendered is not None and s.rendered.key == s.key for s in samples)
    probe = Variation(probe_m_per_k=LAW_M_PER_K)
    day = cost_and_offsets(samples, AssessmentConfig(), satellite="j01", variation=probe)
    assert len({f.parallax_m_per_k for f in day.fors}) == 1  # one scale for the day
