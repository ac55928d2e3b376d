"""The step detector: its pooling, its fitted noise, its windows' sigmas, its thresholds, and the steps it
finds (the rule's path through a store is in test_rules.py)."""

import datetime as dt
import logging

import numpy as np
import pytest

from alerts import noise, steps
from monitor.config.alert_settings import RuleSettings
from monitor.core.constants import N_FOR

RULES = steps.StepRules(1.0, 0.05, 21, 7, 3, 14, 50.0, 1)
DAY0 = dt.date(2025, 1, 1)


def _noise(rng, days, scale=1.0, shared=0.0, lag1=0.0, directions=2):
    common = rng.standard_normal((days, 1, directions))
    e = np.sqrt(shared) * common + np.sqrt(1 - shared) * rng.standard_normal((days, N_FOR, directions))
    for t in range(1, days):
        e[t] = lag1 * e[t - 1] + np.sqrt(1 - lag1**2) * e[t]
    return scale * e


def test_pooling_is_the_generalised_least_squares_step():
    """The closed form equals x^T S^-1 d / x^T S^-1 x with S the exchangeable covariance, FORs missing."""
    rng = np.random.default_rng(1)
    d = rng.normal(0, 10, N_FOR)
    sigma = rng.uniform(5, 20, N_FOR)
    d[[4, 17]] = np.nan
    rho = 0.4
    est, sig = steps.pooled(d, sigma, rho)
    ok = np.isfinite(d)
    cov = rho * np.outer(sigma[ok], sigma[ok]) + (1 - rho) * np.diag(sigma[ok] ** 2)
    inv = np.linalg.inv(cov)
    for g, (name, idx) in enumerate(steps.GROUPS):
        x = np.array([k in idx for k in range(N_FOR)], float)[ok]
        if not x.any():
            assert np.isnan(est[g]), name
            continue
        assert est[g] == pytest.approx(x @ inv @ d[ok] / (x @ inv @ x)), name
        assert sig[g] == pytest.approx(1 / np.sqrt(x @ inv @ x)), name


@pytest.mark.parametrize("scale, shared, lag1", [(1.0, 0.0, 0.0), (1.3, 0.0, 0.0), (1.0, 0.5, 0.3)])
def test_the_noise_is_fitted_not_assumed(scale, shared, lag1):
    """A year of days: the scale within 10 % (sigmas honest or not), the shared share and the day-to-day
    correlation within 0.1; a step and a stuck day cost nothing."""
    rng = np.random.default_rng(2)
    y = 120.0 * _noise(rng, 365, scale, shared, lag1)
    y[200:, :, 0] += 800.0
    y[100] += 5000.0
    fit = steps.fit_noise(np.arange(365), y, np.full_like(y, 120.0))
    assert fit.scale == pytest.approx(scale, rel=0.1)
    assert fit.shared == pytest.approx(shared, abs=0.1)
    assert fit.lag1 == pytest.approx(lag1, abs=0.1)


def test_the_shared_share_is_fitted_precisely():
    """Over 40 histories of 120 days with rho 0.5 and phi 0.3 the fitted rho scatters by less than 0.06 (a
    median-absolute-value variance gave 0.09)."""
    rng = np.random.default_rng(12)
    rho = [steps.fit_noise(np.arange(120), e, np.ones_like(e)).shared for e in
           (_noise(rng, 120, 1.0, 0.5, 0.3) for _ in range(40))]  # fmt: skip
    assert np.std(rho) < 0.06 and abs(np.mean(rho) - 0.5) < 0.03


def test_a_windows_sigma_is_exact_for_days_in_a_row():
    """The running sums' sigma against lambda^2 c^T Phi c with the AR(1) correlation, equal sigmas."""
    ordinal = np.arange(40)
    y = np.zeros((40, N_FOR, 1))
    s = np.full_like(y, 2.0)
    noise = steps.Noise(np.array([1.2]), np.array([0.0]), 0.4)
    for w in (steps._Window(10, 31, 31, 33), steps._Window(10, 31, 32, 35, known=True)):
        _, sig = steps._differences(ordinal, y, s, [w], noise)
        c = np.zeros(40)
        c[w.pre_from : w.pre_to] = -1 / (w.pre_to - w.pre_from)
        c[w.post_from : w.post_to + 1] = 1 / (w.post_to + 1 - w.post_from)
        phi = 0.4 ** np.abs(ordinal[:, None] - ordinal[None, :])
        assert sig[0, 0, 0] == pytest.approx(1.2 * 2.0 * np.sqrt(c @ phi @ c))


def test_thresholds_follow_the_rates():
    blind = steps.threshold(1 / 365, 0.0, 0.0, 21, 3, False, 2, 365)
    rarer = steps.threshold(0.1 / 365, 0.0, 0.0, 21, 3, False, 2, 365)
    assert steps.threshold(0.05, 0.0, 0.0, 21, 3, True, 2, 365) < blind < rarer
    assert 3.5 < blind < 5.5  # ~370 z's a day, much correlated


def test_a_noise_known_from_fewer_days_is_judged_by_a_higher_threshold():
    """The fitted rho, phi and lambda are less certain from three weeks than from a year: the threshold
    pays for it, most where the FORs share their error (a small group's sigma shrinks as sqrt(1 - rho))."""
    weeks, year = (steps.threshold(1 / 365, 0.5, 0.3, 21, 3, False, 2, n) for n in (21, 365))
    assert weeks > year + 0.3
    assert steps.fit_days_bucket(20) == steps.fit_days_bucket(21) == 21
    assert steps.fit_days_bucket(200) == 180 and steps.fit_days_bucket(4000) == 365


def _days(n):
    return [DAY0 + dt.timedelta(days=i) for i in range(n)]


def test_a_step_of_three_fors_is_found_within_three_days_with_its_size():
    """300 urad on FORs 11-13 cross-track at sigma 120, the FORs sharing half their error: found on its day
    or the next two, dated within a day, each FOR's size within its sigmas."""
    rng = np.random.default_rng(4)
    y = 120.0 * _noise(rng, 120, 1.0, 0.5, 0.3)
    y[100:, 10:13, 1] += 300.0
    s = np.full_like(y, 120.0)
    found = []
    for end in range(100, 103):
        found = steps.detect(_days(end + 1), y[: end + 1], s[: end + 1], [], RULES)
        if found:
            break
    (step,) = found
    assert abs((step.split - _days(101)[100]).days) <= 1 and step.change is None and step.paged
    assert step.direction == 1 and step.group in ("FOR 11-13", "FOR 12", "FOR 11", "FOR 13")
    truth = np.zeros(N_FOR)
    truth[10:13] = 300.0
    z = (step.size[:, 1] - truth) / step.sigma[:, 1]
    assert np.sqrt(np.mean(z**2)) < 2.0


def test_a_step_at_a_known_change_is_named_and_the_mixed_day_left_out():
    """The change's day holds half the step: the step is dated the change's day and named after it."""
    rng = np.random.default_rng(5)
    y = 120.0 * _noise(rng, 120)
    y[100:, :, 0] += 200.0
    y[100, :, 0] -= 100.0
    s = np.full_like(y, 120.0)
    (step,) = steps.detect(_days(103), y[:103], s[:103], [_days(101)[100]], RULES)
    assert step.split == _days(101)[100] and step.change == 0
    assert step.pooled == pytest.approx(200.0, abs=4 * step.pooled_sigma)


def test_a_step_is_reported_until_its_new_level_has_held_for_the_baseline_and_starts_a_new_one():
    """200 urad in-track from a known change at day 100: every evaluation reports it (the alert fires) until
    the new level has held for pre_days full days (days 101-121), none after (it resolves); a second step
    30 days later is measured against the new level, not the old one."""
    rng = np.random.default_rng(8)
    y = 60.0 * _noise(rng, 170)
    y[100:, :, 0] += 200.0
    y[130:, :, 0] += 100.0
    s = np.full_like(y, 60.0)
    change = [_days(101)[100]]
    reported = {
        end: steps.detect(_days(end + 1), y[: end + 1], s[: end + 1], change, RULES)
        for end in range(101, 126)
    }
    assert all(any(x.split == change[0] for x in reported[end]) for end in range(101, 122))
    assert all(not any(x.split == change[0] for x in reported[end]) for end in range(122, 126))
    second = [x for x in steps.detect(_days(133), y[:133], s[:133], change, RULES) if x.split != change[0]]
    assert len(second) == 1 and second[0].pooled == pytest.approx(100.0, abs=4 * second[0].pooled_sigma)


def test_small_steps_are_recorded_not_paged_and_noise_finds_nothing():
    rng = np.random.default_rng(6)
    y = 5.0 * _noise(rng, 120)
    s = np.full_like(y, 5.0)
    assert steps.detect(_days(100), y[:100], s[:100], [], RULES) == []
    y[100:, :, 0] += 10.0
    (step,) = steps.detect(_days(103), y[:103], s[:103], [], RULES)
    assert not step.paged and step.pooled == pytest.approx(10.0, abs=4 * step.pooled_sigma)


def test_sigmas_too_small_do_not_page():
    """Sigmas reported a quarter of the scatter: the fitted scale restores it; nothing is found."""
    rng = np.random.default_rng(7)
    y = 120.0 * _noise(rng, 150)
    s = np.full_like(y, 30.0)
    assert steps.detect(_days(150), y, s, [], RULES) == []


def test_the_retired_keys_are_read_with_a_warning(caplog):
    with caplog.at_level(logging.WARNING, logger="monitor.config"):
        r = RuleSettings.model_validate({"min_jump_km": 0.25, "jump_z": 5.0})
    assert r.practical_step_urad == pytest.approx(300.1, abs=0.1)
    assert "alerts.min_jump_km (0.25 km) is read as alerts.practical_step_urad 300" in caplog.text
    assert "alerts.jump_z is no longer used" in caplog.text


def test_the_replay_window_with_the_kept_fits_finds_what_the_whole_history_finds():
    """Two years with a step at a known change and one blind step near the end: detect on the last
    replay_reach days, given the fits of the whole history before each refit date (as the store keeps
    them), finds the same steps, sizes and sigmas as detect on the whole history, asking for each fit once."""
    rng = np.random.default_rng(12)
    n = 730
    y = 120.0 * _noise(rng, n, 1.0, 0.3, 0.2)
    s = np.full_like(y, 120.0)
    s[:, 5] = 200.0  # a FOR with its own usual sigma: the floor comes from the kept fit
    y[n - 15 :, :, 0] += 300.0
    y[n - 5 :, 20:23, 1] += 600.0
    days = _days(n)
    change = [days[100], days[n - 15]]
    ordinal = np.array([d.toordinal() for d in days])
    asked = []

    def kept(before):
        asked.append(before)
        return noise.fitted_before(ordinal, y, s, before)

    start = ordinal[-1] - steps.replay_reach(RULES)
    window = ordinal >= start
    whole = steps.detect(days, y, s, change, RULES)
    part = steps.detect(
        [d for d, w in zip(days, window, strict=True) if w], y[window], s[window], change, RULES, kept
    )
    assert len(whole) == 2 and {x.change for x in whole} == {1, None}
    assert [(x.split, x.change, x.seen, x.group, x.direction) for x in part] == [
        (x.split, x.change, x.seen, x.group, x.direction) for x in whole
    ]
    for a, b in zip(part, whole, strict=True):
        assert a.z == pytest.approx(b.z, rel=1e-9) and a.pooled == pytest.approx(b.pooled, rel=1e-9)
        np.testing.assert_allclose(a.sigma, b.sigma, rtol=1e-9)
    # refit dates on or before the splits' baselines, each asked once
    assert len(asked) == len(set(asked)) and max(asked) <= ordinal[-1] - RULES.baseline_days


def test_a_fit_survives_its_round_trip_through_json():
    """What the store keeps (FittedNoise.to_dict, as JSON) is the fit itself, NaN sigmas included."""
    import json

    rng = np.random.default_rng(13)
    y = 50.0 * _noise(rng, 60)
    s = np.full_like(y, 50.0)
    s[:, 3, 0] = np.nan  # a FOR never measured: no usual sigma
    fitted = noise.fitted_before(np.arange(60), y, s, 40)
    back = noise.FittedNoise.from_dict(json.loads(json.dumps(fitted.to_dict())))
    assert back.days == 40 and np.isnan(back.typical[3, 0])
    np.testing.assert_array_equal(back.typical, fitted.typical)
    np.testing.assert_array_equal(back.noise.scale, fitted.noise.scale)
    np.testing.assert_array_equal(back.noise.shared, fitted.noise.shared)
    assert back.noise.lag1 == fitted.noise.lag1
    young = noise.fitted_before(np.arange(60), y, s, 10)  # too few days: counted, not fitted
    assert young.noise is None and noise.FittedNoise.from_dict(young.to_dict()).noise is None
