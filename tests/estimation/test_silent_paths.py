"""Nothing silent: each way the estimate departs from the configured one is flagged, in the result, with
the error of the kernel actually used (each path forced here on synthetic samples)."""

from dataclasses import replace

import numpy as np
import pytest

from monitor.config.assessment import AssessmentConfig
from monitor.core.result import FLAG_FLAT, FLAG_TOP_HAT, FLAG_UNCONVERGED
from monitor.core.vocabulary import Cost
from monitor.estimation import estimate as est
from monitor.estimation import offsets
from monitor.instrument import footprint
from tests.estimation.test_estimate import STEP_RAD, _samples

STEP_URAD = STEP_RAD * 1e6


def test_too_few_fovs_for_the_footprint_is_the_cones_estimate_flagged_with_the_cones_error():
    """A FOR below MIN_FOOTPRINT_SAMPLES takes the cone's estimate, flagged, its sigma carrying the day's
    own measure of the cone's error: how far the cone's minimum lies from the footprint's at the FORs that
    fitted a response (here one)."""
    few = _samples(footprint.super_gaussian(), n=36)
    assert len(few) < est.MIN_FOOTPRINT_SAMPLES
    enough = _samples(footprint.super_gaussian(), n=160)
    cfg = AssessmentConfig(min_samples=10)
    alone, fitted = offsets.day_offsets([few, enough], cfg, STEP_URAD).fors
    assert FLAG_TOP_HAT in alone.flags and alone.reliable  # said, and still usable
    assert FLAG_TOP_HAT not in fitted.flags and np.isfinite(fitted.response_width_50_urad)
    day = est.estimate(enough, Cost.REGRESSION)
    cone_error = np.abs(np.subtract(day.cone, (day.x, day.y))) * STEP_URAD
    assert cone_error.max() > 1.0  # the smooth truth moves the cone's minimum
    assert alone.sigma_alpha_urad >= cone_error[0] and alone.sigma_beta_urad >= cone_error[1]
    # a day without a fitted response has no measure of it: the jackknife's sigma alone
    (bare,) = offsets.day_offsets([few], cfg, STEP_URAD).fors
    jack = est.estimate(few, Cost.REGRESSION).sigma
    assert bare.sigma_alpha_urad == pytest.approx(jack[0] * STEP_URAD)


def test_a_replicate_fits_the_footprint_whenever_the_day_does():
    """44 FOVs in 4 granules: the day fits the response, each replicate keeps 33 (fewer than 40) and fits it
    too, so the widths get a jackknife sigma (they had none when the replicates fell back to the cone)."""
    s = _samples(footprint.super_gaussian(), n=44)
    fit = est.estimate(s, Cost.REGRESSION)
    assert fit.footprint is not None and np.isfinite(fit.footprint.sigma_width_50_rad)


def test_an_alternation_that_runs_out_is_flagged(monkeypatch):
    monkeypatch.setattr(est, "FOOTPRINT_ITERATIONS", 1)
    monkeypatch.setattr(est, "CONVERGED_STEPS", 0.0)  # never converged
    fit = est.estimate(_samples(footprint.super_gaussian(), n=160), Cost.REGRESSION)
    assert FLAG_UNCONVERGED in fit.flags


def test_a_refit_that_finds_the_surface_flat_says_so(monkeypatch):
    real, calls = est._minimum, []

    def flat_on_refit(*args, **kw):
        m = real(*args, **kw)
        calls.append(m)
        return m if len(calls) == 1 else replace(m, refined=False, flags=[FLAG_FLAT])

    monkeypatch.setattr(est, "_minimum", flat_on_refit)
    fit = est.estimate(_samples(footprint.super_gaussian(), n=160), Cost.REGRESSION, uncertainty=False)
    assert FLAG_FLAT in fit.flags  # the earlier minimum is kept, and the refit's word with it
