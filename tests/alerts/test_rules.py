import dataclasses
import datetime as dt

import numpy as np
import pytest

from alerts.engine import findings_for
from alerts.rules import CALIBRATION, GEOLOCATION, failure_finding, jump_findings, spec_finding, stale_finding
from monitor.config.alert_settings import AlertSettings, RuleSettings
from monitor.core.result import AssessmentResult, ForOffset, GranuleInfo
from monitor.history.changes import (
    Change,
    add_to_calendar,
    all_changes,
    load_calendar,
    metadata_changes,
    preceding_change,
)
from monitor.service.store.sqlite import Store

DAY = dt.date(2024, 6, 1)
UTC = dt.timezone.utc


def _for(k, it, ct, sig=0.05, flags=()):
    return ForOffset(
        k, 0.0, 0.0, 10.0, 10.0, it, ct, float(np.hypot(it, ct)), sig, sig, 100, 0.1, 0.2, tuple(flags)
    )


def _result(fors, granules=()):
    return AssessmentResult("j01", "", "", fors, list(granules))


def _granule(gid, cris_aux, viirs_aux, sw="I2.1.03.00"):
    return GranuleInfo(
        granule_id=gid,
        start="t",
        end="t",
        cris_geo="g",
        cris_sdr="s",
        viirs=[],
        n_fovs=1,
        n_usable=1,
        cris_meta={"aux_files": cris_aux, "software_version": sw, "algorithm_version": "2.O"},
        viirs_meta={"aux_files": viirs_aux, "software_version": "I2.0"},
    )


def test_spec_severity_uses_the_uncertainty(tmp_path):
    s = Store(tmp_path / "s.sqlite")
    fors = [_for(k, 0.1, 0.2) for k in range(1, 31)]
    fors[27] = _for(28, 0.2, 1.6, sig=0.2)  # 1.6 - 2 x 0.2 < 1.5: warning
    fors[29] = _for(30, -0.7, 4.4, sig=0.1)  # critical
    fors[28] = _for(29, 0.1, 3.0, flags=("flat",))  # unreliable: never alerts
    s.save_day(s.begin_run("j01", DAY), "j01", DAY, _result(fors))
    f = spec_finding(s, "j01", RuleSettings())
    assert f.severity == "critical" and f.data["fors"] == [28, 30]
    assert "within 2 sigma" in f.lines[0] and "within 2 sigma" not in f.lines[1]
    fors[29] = _for(30, -0.7, 1.55, sig=0.1)
    s.save_day(s.begin_run("j01", DAY), "j01", DAY, _result(fors))
    assert spec_finding(s, "j01", RuleSettings()).severity == "warning"


def test_stale_and_failure(tmp_path):
    s = Store(tmp_path / "s.sqlite")
    assert stale_finding(s, "j01", RuleSettings(), dt.datetime.now(UTC)) is None
    run = s.begin_run("j01", DAY)
    s.finish_run(run, "failed", "SourceError: listing: HTTP 503")
    f = failure_finding(s, "j01")
    assert f.severity == "critical" and "HTTP 503" in f.lines[0]
    later = dt.datetime.now(UTC) + dt.timedelta(hours=40)
    assert "no successful assessment" in stale_finding(s, "j01", RuleSettings(), later).lines[0]
    s.save_day(s.begin_run("j01", DAY), "j01", DAY, _result([_for(k, 0, 0) for k in range(1, 31)]))
    assert (
        failure_finding(s, "j01") is None
        and stale_finding(s, "j01", RuleSettings(), dt.datetime.now(UTC)) is None
    )


def test_metadata_changes_name_the_instrument(tmp_path):
    s = Store(tmp_path / "s.sqlite")
    viirs_lut = (
        "VIIRS-SDR-GEO-IMG-PARAM-LUT_j01_20130601000000Z_20130601000000Z_ee00000000000000Z_PS-1-O-CCR-{}_all"
    )
    cris = ["CrIS-SDR-CC_j01_20180426000000Z_x_ops", "CrIS-SDR-ENGPKT-BACKUP-AUX_j01_{}_ops"]
    for i, (vl, eng) in enumerate([("1171", "a"), ("1171", "b"), ("2042", "c")]):
        day = DAY + dt.timedelta(days=i)
        g = _granule(f"J{i}", [cris[0], cris[1].format(eng)], [viirs_lut.format(vl)])
        s.save_day(s.begin_run("j01", day), "j01", day, _result([_for(1, 0, 0)], [g]))
    changes = metadata_changes(s, "j01")
    assert len(changes) == 1  # the engineering-packet backup AUX changes every run and is ignored
    assert changes[0].instrument == "viirs" and "2042" in changes[0].description
    assert changes[0].time.date() == DAY + dt.timedelta(days=2)
    # from a day on, as the daily evaluation reads them: the changes after that day, the calendar's too
    (tmp_path / "events.yaml").write_text(
        f"events:\n  - {{satellite: j01, time: '{DAY}T12:00:00Z', instrument: cris, kind: ep_upload}}\n"
    )
    assert all_changes(s, "j01", tmp_path / "events.yaml", since=DAY + dt.timedelta(days=1)) == changes
    assert all_changes(s, "j01", tmp_path / "events.yaml", since=DAY + dt.timedelta(days=2)) == []
    assert len(all_changes(s, "j01", tmp_path / "events.yaml")) == 2


def test_a_bias_jump_after_a_viirs_lut_change_is_a_calibration_jump_attributed_to_viirs(tmp_path):
    """40 days of a CrIS-VIIRS bias of 0.2 K (day-to-day scatter 0.02 K), 0.3 K more from the day a new
    VIIRS LUT appears in the granules' metadata; the offsets do not move. One calibration finding,
    attributed to VIIRS; no geolocation jump; the same days without the step: nothing."""
    lut = (
        "VIIRS-SDR-GEO-IMG-PARAM-LUT_j01_20130601000000Z_20130601000000Z_ee00000000000000Z_PS-1-O-CCR-{}_all"
    )
    cris = ["CrIS-SDR-CC_j01_20180426000000Z_x_ops"]
    days = [DAY + dt.timedelta(days=i) for i in range(40)]
    split = days[34]
    for step_k, name in ((0.3, "step"), (0.0, "flat")):
        s = Store(tmp_path / f"{name}.sqlite")
        rng = np.random.default_rng(3)
        for day in days:
            bias = 0.2 + rng.normal(0.0, 0.02, 30) + (step_k if day >= split else 0.0)
            fors = [
                dataclasses.replace(
                    _for(k, 0.1, 0.2), bias_k=float(bias[k - 1]), sigma_bias_k=0.02, gain_pct=0.1
                )
                for k in range(1, 31)
            ]
            g = _granule(f"J{day}", cris, [lut.format("2042" if day >= split else "1171")])
            s.save_day(s.begin_run("j01", day), "j01", day, _result(fors, [g]))
        changes = metadata_changes(s, "j01")
        found = jump_findings(s, "j01", changes, RuleSettings(), CALIBRATION)
        assert jump_findings(s, "j01", changes, RuleSettings(), GEOLOCATION) == []
        if not step_k:
            assert found == []
            continue
        (f,) = found
        assert f.rule == "calibration_jump" and f.data["split"] == split.isoformat()
        assert f.data["instrument"] == "viirs" and "2042" in f.data["change"]
        assert "CrIS-VIIRS calibration step" in f.summary and "bias +0.30" in f.lines[0]
        sizes = f.data["fors"]["bias"]
        assert all(abs(v - 0.3) < 4 * e for v, e in zip(sizes["size"], sizes["sigma"], strict=True))
        rules = [x.rule for x in findings_for(s, "j01", AlertSettings(), dt.datetime.now(UTC))]
        assert "calibration_jump" in rules and "jump" not in rules


def test_calendar_round_trip_and_attribution(tmp_path):
    cal = tmp_path / "events.yaml"
    c = Change(dt.datetime(2014, 2, 27, tzinfo=UTC), "npp", "cris", "ep_upload", "EP v36", "calendar")
    add_to_calendar(cal, c)
    (back,) = load_calendar(cal)
    assert back == c
    assert preceding_change([back], dt.date(2014, 2, 28)) == back
    assert preceding_change([back], dt.date(2014, 2, 26)) is None
    assert preceding_change([back], dt.date(2014, 3, 30)) is None  # too long after
    cal.write_text("events:\n  - {satellite: npp, time: 2014-01-01, instrument: modis}\n")
    with pytest.raises(ValueError, match=r"events\[0\]: instrument 'modis'"):
        load_calendar(cal)


def test_shipped_calendar_holds_the_known_history():
    from pathlib import Path

    events = load_calendar(Path(__file__).resolve().parents[2] / "configs" / "events.yaml")
    assert any(e.kind == "ep_upload" and e.time.date() == dt.date(2014, 2, 27) for e in events)
    assert any(
        e.instrument == "viirs" and e.time == dt.datetime(2012, 11, 22, 16, 32, tzinfo=UTC) for e in events
    )


def _offsets_day(store, day, alpha, beta, sigma):
    fors = [
        dataclasses.replace(
            _for(k + 1, 0.1, 0.2), d_alpha_urad=float(alpha[k]), d_beta_urad=float(beta[k]),
            sigma_alpha_urad=sigma, sigma_beta_urad=sigma,
        )
        for k in range(30)
    ]  # fmt: skip
    store.save_day(store.begin_run("j01", day), "j01", day, _result(fors))


def test_a_step_at_an_ep_upload_is_paged_once_naming_it_and_a_small_one_only_recorded(tmp_path):
    """Through the store and evaluate, day by day: 300 urad cross-track on FORs 11-13 from an EP upload at
    noon on day 80 (sigma 120): the first message names the upload, within 3 days; 10 urad on every FOR at
    sigma 5 is recorded (severity info) and sends nothing."""
    from alerts.engine import evaluate

    days = [DAY + dt.timedelta(days=i) for i in range(84)]
    upload = days[80]
    (tmp_path / "events.yaml").write_text(
        f"events:\n  - {{satellite: j01, time: '{upload}T12:00:00Z', instrument: cris, kind: ep_upload, "
        "description: EP v116}\n"
    )
    cfg = AlertSettings.model_validate({"events_file": str(tmp_path / "events.yaml")})
    rng = np.random.default_rng(11)
    big, small = Store(tmp_path / "big.sqlite"), Store(tmp_path / "small.sqlite")
    sent = []
    for i, day in enumerate(days):
        beta = rng.normal(0.0, 120.0, 30)
        beta[10:13] += 300.0 * (i > 80) + 150.0 * (i == 80)
        _offsets_day(big, day, rng.normal(0.0, 120.0, 30), beta, 120.0)
        _offsets_day(small, day, rng.normal(0.0, 5.0, 30) + 10.0 * (i >= 80), rng.normal(0.0, 5.0, 30), 5.0)
        now = dt.datetime.combine(day + dt.timedelta(days=1), dt.time(4), UTC)
        if i >= 60:
            sent += [(i, m) for _, m in evaluate(big, cfg, ["j01"], now)]
            assert evaluate(small, cfg, ["j01"], now) == []
    (first, message), *_ = sent
    assert 80 <= first <= 82 and "step from " + str(upload) in message.text
    assert "EP v116" in message.text and "no known change" not in message.text
    (alert,) = [a for a in big.alert_state().all() if a.rule == "jump"]
    assert alert.grp == str(upload) and alert.severity == "warning"
    (recorded,) = [a for a in small.alert_state().all() if a.rule == "jump" and a.grp == str(upload)]
    assert recorded.severity == "info" and recorded.status == "firing"
    assert all(a.severity == "info" for a in small.alert_state().all())  # recorded, nothing sent


def test_the_jump_rule_reads_its_kept_noise_and_fits_anew_once_an_earlier_day_is_stored_again(tmp_path):
    """A year with a cross-track step ten days before its end: the first evaluation keeps a noise fit per
    refit date it uses; the next one reads them back (a kept fit made 100 times too wide hides the step);
    storing an earlier day again, as a reprocessing does, drops the fits after that day, and the step is
    found again as a store filled once finds it."""
    from monitor.simulate.history import day_result, fill_store

    days = fill_store(Store(tmp_path / "fresh.sqlite"), ["j01"], DAY, 365, step_day=355, step_urad=60.0)
    store = Store(tmp_path / "fresh.sqlite")
    settings, now = AlertSettings(), dt.datetime.combine(days[-1], dt.time(6), UTC) + dt.timedelta(days=1)
    first = [f.alert_id for f in findings_for(store, "j01", settings, now)]
    assert first == [f"jump:j01:{days[355]}"]
    kept = store.noise_fits("j01", "jump")
    assert kept and all(before <= days[-1] for before in kept)
    for before, body in kept.items():  # each kept fit made 100 times too wide
        store.keep_noise_fit("j01", "jump", before, {**body, "scale": [100.0, 100.0]})
    assert [f.alert_id for f in findings_for(store, "j01", settings, now)] == []  # read back, not refitted
    again = days[200]
    store.save_day(
        store.begin_run("j01", again), "j01", again, day_result("j01", again, np.random.default_rng(1))
    )
    left = store.noise_fits("j01", "jump")
    assert all(before <= again for before in left)
    assert [f.alert_id for f in findings_for(store, "j01", settings, now)] == first


def _bands_day(rng, levels_k, sigma_k=0.02):
    """30 FORs with CrIS minus VIIRS in each band of *levels_k* at its level plus noise of *sigma_k*."""
    fors = []
    for k in range(1, 31):
        values = {}
        for band, level in levels_k.items():
            values[f"cris_minus_viirs_k_{band}"] = float(level + rng.normal(0.0, sigma_k))
            values[f"sigma_cris_minus_viirs_k_{band}"] = sigma_k
        fors.append(dataclasses.replace(_for(k, 0.1, 0.2), **values))
    return fors


def test_a_band_beyond_the_radiometry_limit_pages_as_the_spec_does(tmp_path):
    s = Store(tmp_path / "s.sqlite")
    rng = np.random.default_rng(5)
    fors = _bands_day(rng, {"I5": 0.05, "M15": 0.02})
    fors[9] = dataclasses.replace(fors[9], cris_minus_viirs_k_M15=0.8)  # beyond 0.5 K by 2 sigma: critical
    s.save_day(s.begin_run("j01", DAY), "j01", DAY, _result(fors))
    (f,) = [
        x for x in findings_for(s, "j01", AlertSettings(), dt.datetime.now(UTC)) if x.rule == "radiometry"
    ]
    assert f.severity == "critical" and f.data == {"day": DAY.isoformat(), "bands": ["M15"], "fors": [10]}
    assert "M15 FOR 10: CrIS minus VIIRS +0.800" in f.lines[0]
    fors[9] = dataclasses.replace(fors[9], cris_minus_viirs_k_M15=0.52)  # within 2 sigma of it: a warning
    s.save_day(s.begin_run("j01", DAY), "j01", DAY, _result(fors))
    assert findings_for(s, "j01", AlertSettings(), dt.datetime.now(UTC))[0].severity == "warning"
    quiet = AlertSettings(radiometry_limit_k=1.0)
    assert not [x for x in findings_for(s, "j01", quiet, dt.datetime.now(UTC)) if x.rule == "radiometry"]


@pytest.mark.parametrize("moved", [("M15",), ("I5", "M15", "M16")])
def test_a_step_in_one_band_is_viirs_and_in_every_lw_band_cris(tmp_path, moved):
    """40 days of four bands (scatter 0.02 K, as their sigmas say), 0.1 K more in *moved* from day 35, no
    calendar entry, the offsets steady: each moved band pages a calibration_jump of its own, told VIIRS's
    where one band moved and CrIS's where every band of CrIS's long-wave band did."""
    s = Store(tmp_path / "s.sqlite")
    rng = np.random.default_rng(11)
    days = [DAY + dt.timedelta(days=i) for i in range(40)]
    levels = {"I5": 0.05, "M13": -0.04, "M15": 0.03, "M16": -0.02}
    for i, day in enumerate(days):
        step = {b: (0.1 if b in moved and i >= 34 else 0.0) for b in levels}
        fors = _bands_day(rng, {b: v + step[b] for b, v in levels.items()})
        s.save_day(s.begin_run("j01", day), "j01", day, _result(fors))
    found = [
        x
        for x in findings_for(s, "j01", AlertSettings(), dt.datetime.now(UTC))
        if x.rule == "calibration_jump"
    ]
    assert sorted(f.data["band"] for f in found) == sorted(moved)
    assert len({f.alert_id for f in found}) == len(found)  # one alert per band
    for f in found:
        assert f.severity == "warning" and abs(f.data["size"] - 0.1) < 0.03
        assert f.data["evidence"] == ("viirs" if len(moved) == 1 else "cris"), f.lines
        assert ("VIIRS's" if len(moved) == 1 else "CrIS's") in f.summary
