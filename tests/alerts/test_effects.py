"""What a known change did, measured on a real store: before and after, the move with its sigma, its
significance, and the move the EPs' mapping angles predict."""

import dataclasses
import datetime as dt

import numpy as np

from alerts.effects import change_effects, effect_text
from monitor.config.alert_settings import RuleSettings
from monitor.core.result import AssessmentResult, ForOffset
from monitor.history.changes import Change
from monitor.service.store.sqlite import Store

UTC = dt.timezone.utc
DAY = dt.date(2024, 3, 1)
KM_PER_URAD = 0.00083  # about 830 km of range at nadir
SIGMA_URAD = 20.0


def _day(store, day, alpha, beta, sigma=SIGMA_URAD):
    fors = [
        ForOffset(
            k + 1, float(alpha[k]), float(beta[k]), sigma, sigma, float(alpha[k]) * KM_PER_URAD,
            float(beta[k]) * KM_PER_URAD, 0.0, sigma * KM_PER_URAD, sigma * KM_PER_URAD, 100, 0.1, 0.2, (),
        )
        for k in range(30)
    ]  # fmt: skip
    store.save_day(store.begin_run("j01", day), "j01", day, AssessmentResult("j01", "", "", fors, []))


def _print(store, day, los_urad, ep, model_urad):
    """A stored LOS fingerprint whose best EP match is *ep* with model angles *model_urad* (30, 2)."""
    residual = los_urad - model_urad
    store.save_fingerprint(
        "j01",
        day,
        {
            "fors": [
                {"for": k + 1, "alpha_urad": los_urad[k, 0], "beta_urad": los_urad[k, 1]} for k in range(30)
            ],
            "ep_match": [
                {
                    "name": f"JPSS1_side1_{ep}_EngPkt.xml",
                    "version": ep,
                    "rms_urad": float(np.sqrt(np.mean(residual**2))),
                    "d_alpha_urad": residual[:, 0].tolist(),
                    "d_beta_urad": residual[:, 1].tolist(),
                }
            ],
        },
    )


def _history(tmp_path, observed_sign=1.0, seed=3):
    """60 days; an EP upload at noon on day 40 turns the GEO's LOS by delta (FORs 11-20 in-track +80 urad,
    21-30 cross-track -60 urad, 1-10 not at all); the offsets move by observed_sign * -delta. A VIIRS LUT
    change on day 50 ends the window after the upload."""
    rng = np.random.default_rng(seed)
    level = rng.normal(0.0, 100.0, (30, 2))
    delta = np.zeros((30, 2))
    delta[10:20, 0], delta[20:30, 1] = 80.0, -60.0
    model_old = rng.normal(0.0, 1000.0, (30, 2))
    servo = rng.normal(0.0, 20.0, (30, 2))  # what the EP model leaves in the GEO's angles
    store = Store(tmp_path / "s.sqlite")
    for i in range(60):
        day = DAY + dt.timedelta(days=i)
        after = i > 40
        y = level - observed_sign * delta * after + rng.normal(0.0, SIGMA_URAD, (30, 2))
        if i == 40:
            y = y - 0.5 * delta  # the upload's day holds both levels
        _day(store, day, y[:, 0], y[:, 1])
        model = model_old + delta * after
        _print(store, day, model + servo, "V116" if after else "V115", model)
    changes = [
        Change(dt.datetime(2024, 4, 10, 12, tzinfo=UTC), "j01", "cris", "ep_upload", "EP V116", "calendar"),
        Change(dt.datetime(2024, 4, 20, 3, tzinfo=UTC), "j01", "viirs", "lut_change", "I5 LUT", "metadata"),
    ]
    return store, changes, level, delta


def test_the_move_of_each_for_is_measured_with_its_sigma_and_the_eps_prediction_holds(tmp_path):
    store, changes, level, delta = _history(tmp_path)
    first, second = change_effects(store, "j01", changes, RuleSettings())
    assert first.day == dt.date(2024, 4, 10) and first.changes == (changes[0],)
    # 21 days before, the upload's day left out, and after it up to the day before the LUT change
    assert first.before == (dt.date(2024, 3, 20), dt.date(2024, 4, 9))
    assert first.after == (dt.date(2024, 4, 11), dt.date(2024, 4, 19))
    z_before = (first.before_urad - level) / first.sigma_before_urad
    z_move = (first.move_urad + delta) / first.sigma_move_urad
    for z in (z_before, z_move):
        assert 0.7 < np.sqrt(np.mean(z**2)) < 1.3  # honest sigmas
    assert np.allclose(first.sigma_move_urad, SIGMA_URAD * np.sqrt(1 / 21 + 1 / 9), rtol=0.2)
    assert np.allclose(first.move_km, first.move_urad * KM_PER_URAD)
    moved = delta != 0
    assert first.significant[moved].mean() > 0.95 and first.significant[~moved].sum() <= 1
    assert abs(first.common_move_urad[0] + 80.0 / 3) < 3 * first.sigma_common_move_urad[0]
    # the EPs are named from the fingerprints, and their mapping angles predict the move
    assert "V115" in first.ep_before and "V116" in first.ep_after
    assert np.allclose(first.predicted_urad, -delta, atol=0.1)
    assert first.dof == 60 and first.p_value > 0.001
    # the LUT change: no EP named anew, nothing predicted; its before window starts after the upload's day
    assert second.predicted_urad is None and second.before[0] == dt.date(2024, 4, 11)
    assert not second.significant.any()
    text = "\n".join(effect_text(first))
    assert "EP V116" in text and "predicted" in text and "chi2" in text and text.count("\n") > 60


def test_a_move_against_the_prediction_is_rejected(tmp_path):
    store, changes, _, _ = _history(tmp_path, observed_sign=-1.0)
    first, _ = change_effects(store, "j01", changes, RuleSettings())
    assert first.p_value < 1e-6


def test_a_change_without_days_on_both_sides_is_not_measured(tmp_path):
    store, changes, _, _ = _history(tmp_path)
    late = dataclasses.replace(changes[1], time=dt.datetime(2024, 4, 30, 12, tzinfo=UTC))
    assert [e.day for e in change_effects(store, "j01", [changes[0], late], RuleSettings())] == [
        dt.date(2024, 4, 10)
    ]
