"""The day's estimate in one call: each FOR built once, the same records whether the FORs wait for the day's
lift in memory or in the day's spool, and no lift without a rendered collocation."""

from dataclasses import replace

import numpy as np

from monitor.assessment.spool import Spool
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR
from monitor.estimation.day_estimate import DaySamples, PerFor, estimate_day
from monitor.estimation.offsets import NO_LIFT, day_offsets
from monitor.instrument import footprint
from tests.estimation.test_estimate import STEP_RAD, _samples
from tests.estimation.test_offsets import _jacobian

CFG = AssessmentConfig(min_samples=10, step_urad=STEP_RAD * 1e6)


def _day(keep=None):
    s0 = _samples(footprint.super_gaussian(), n=48, seed=3)
    # the rendered twin: the same FOVs, their surfaces moved a little, as a lift would move them
    s1 = replace(
        s0, d_k=s0.d_k + 0.05 * np.linspace(-1, 1, s0.d_k.shape[-1]), annuli_rad=s0.annuli_rad * 1.001
    )
    built = {"at_geo": 0, "rendered": 0}

    def build(which, s):
        def one(k):
            built[which] += 1
            return s

        return one

    extra = {} if keep is None else {"keep": keep}
    day = DaySamples(build("at_geo", s0), build("rendered", s1), _jacobian, np.zeros(4, bool), 260.0, **extra)
    return day, built, s0


def test_each_for_is_built_once_and_the_spool_changes_no_number():
    day, built, _ = _day()
    in_memory = estimate_day(day, CFG)
    assert built == {"at_geo": N_FOR, "rendered": N_FOR}
    spool = Spool()
    try:
        parked = estimate_day(_day(spool.parked)[0], CFG)
    finally:
        spool.close()
    assert [f.to_dict() for f in parked.fors] == [f.to_dict() for f in in_memory.fors]
    assert len({f.parallax_m_per_k for f in in_memory.fors}) == 1  # one lift for the day, kept or not


def test_a_day_not_rendered_is_estimated_without_a_lift():
    day, built, s0 = _day()
    plain = estimate_day(replace(day, rendered=None), CFG)
    assert built["rendered"] == 0
    direct = day_offsets(PerFor(lambda k: s0), CFG, CFG.step_urad, _jacobian, np.zeros(4, bool), NO_LIFT)
    assert [f.to_dict() for f in plain.fors] == [f.to_dict() for f in direct.fors]
    assert all(np.isnan(f.parallax_m_per_k) for f in plain.fors)
