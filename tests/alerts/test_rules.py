import dataclasses
import datetime as dt

import numpy as np
import pytest

from alerts.engine import findings_for
from alerts.rules import CALIBRATION, GEOLOCATION, failure_finding, jump_findings, spec_finding, stale_finding
from benchmarks.jump_detection import false_alarms, jump_trial
from monitor.config.alert_settings import AlertSettings, RuleSettings
from monitor.core.result import AssessmentResult, ForOffset, GranuleInfo
from monitor.history.changes import Change, add_to_calendar, load_calendar, metadata_changes, preceding_change
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
                dataclasses.replace(_for(k, 0.1, 0.2), bias_k=float(bias[k - 1]), gain_pct=0.1)
                for k in range(1, 31)
            ]
            g = _granule(f"J{day}", cris, [lut.format("2042" if day >= split else "1171")])
            s.save_day(s.begin_run("j01", day), "j01", day, _result(fors, [g]))
        changes = metadata_changes(s, "j01")
        found = jump_findings(s, "j01", changes, RuleSettings(), days[-1], CALIBRATION)
        assert jump_findings(s, "j01", changes, RuleSettings(), days[-1], GEOLOCATION) == []
        if not step_k:
            assert found == []
            continue
        (f,) = found
        assert f.rule == "calibration_jump" and f.data["split"] == split.isoformat()
        assert f.data["instrument"] == "viirs" and "2042" in f.data["change"]
        assert "CrIS-VIIRS calibration jump" in f.summary and "+0.30 K" in f.lines[0]
        assert f.data["fors"] == list(range(1, 31))
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


def test_jumps_found_and_attributed_and_noise_stays_quiet():
    """A reduced run of benchmarks/jump_detection.py (the full figures are in the issue notes)."""
    rng = np.random.default_rng(7)
    s = RuleSettings()
    res = [jump_trial(rng, 0.3, s) for _ in range(12)]
    assert sum(r[0] for r in res) >= 11 and all(r[1] for r in res if r[0])
    assert sum(false_alarms(rng, 1, s)) <= 1
