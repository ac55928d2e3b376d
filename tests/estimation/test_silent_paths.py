"""Nothing silent: each way the estimate departs from the configured one is flagged, in the result, with
the floor of the kernel actually used (each path forced here on synthetic samples)."""

from dataclasses import replace

import numpy as np

from monitor.config.assessment import AssessmentConfig
from monitor.core.result import FLAG_FLAT, FLAG_TOP_HAT, FLAG_UNCONVERGED
from monitor.core.vocabulary import Cost, Kernel
from monitor.estimation import estimate as est
from monitor.instrument import footprint
from tests.estimation.test_estimate import STEP_RAD, _samples

STEP_URAD = STEP_RAD * 1e6


def test_too_few_fovs_for_the_footprint_is_the_cones_estimate_flagged_with_the_cones_floor():
    few = _samples(footprint.super_gaussian(), n=36)  # below MIN_FOOTPRINT_SAMPLES
    assert len(few) < est.MIN_FOOTPRINT_SAMPLES
    cfg = AssessmentConfig(min_samples=10)
    (f,) = est.day_offsets([few], cfg, STEP_URAD).fors
    assert FLAG_TOP_HAT in f.flags and f.reliable  # said, and still usable
    assert min(f.sigma_alpha_urad, f.sigma_beta_urad) >= est.SIGMA_FLOOR_URAD[Kernel.TOP_HAT]
    enough = _samples(footprint.super_gaussian(), n=160)
    (g,) = est.day_offsets([enough], cfg, STEP_URAD).fors
    assert FLAG_TOP_HAT not in g.flags and np.isfinite(g.response_width_50_urad)


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
