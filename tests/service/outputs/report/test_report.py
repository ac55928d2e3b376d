"""The HTML trend report: empty store, one run, years of runs; opened in a real headless Chromium."""

import dataclasses
import datetime as dt
import json
import math
import os
import shutil

import pytest
import yaml
from selenium.webdriver.support.ui import WebDriverWait

from alerts.rules import Finding
from benchmarks.servers import chromium_driver
from monitor.cli import main
from monitor.core.result import AssessmentResult
from monitor.core.vocabulary import Rule, Severity
from monitor.service.outputs.report.html import PAGE_BUDGET_BYTES, ReportOptions, build_report
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store
from monitor.simulate.history import fill_store

SATS = ["npp", "j01", "j02"]
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def store(tmp_path):
    s = Store(tmp_path / "s.sqlite")
    yield s
    s.close()


def _calendar(tmp_path, day):
    path = tmp_path / "events.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "events": [
                    {
                        "time": f"{day}T00:00:00Z",
                        "satellite": "j01",
                        "instrument": "cris",
                        "kind": "ep_upload",
                        "description": "EP V116 uploaded",
                    }
                ]
            }
        )
    )
    return path


def test_empty_store(store, tmp_path):
    index = build_report(store, tmp_path / "rep", ReportOptions(satellites=SATS))
    assert "no data" in index.read_text()
    for sat in SATS:
        page = (tmp_path / "rep" / sat / "index.html").read_text()
        assert "No assessment in the store" in page and "<img" not in page


def test_single_run(store, tmp_path):
    fill_store(store, ["j01"], dt.date(2026, 11, 20), 1)
    build_report(store, tmp_path / "rep", ReportOptions(satellites=["j01"]))
    sat = tmp_path / "rep" / "j01"
    for name in (
        "latest_km",
        "latest_urad",
        "heatmap",
        "trend",
        "cost",
        "calibration_bins",
        "calibration_trend",
    ):
        assert (sat / f"{name}.png").read_bytes()[:8] == PNG
    page = (sat / "index.html").read_text()
    assert "CrIS-VIIRS intercalibration" in page and "No intercalibration stored" not in page
    assert "2026-11-20" in page and "Latest values" in page and "http" not in page.split("<body>")[1]


def test_days_stored_before_the_intercalibration_say_so_and_plot_none(store, tmp_path):
    """A day whose result has no intercalibration (a store from before it): the section says so, and no
    figure of an earlier report for it stays behind."""
    (day,) = fill_store(store, ["j01"], dt.date(2026, 11, 20), 1)
    build_report(store, tmp_path / "rep", ReportOptions(satellites=["j01"]))
    result = store.day_result("j01", day)
    bare = AssessmentResult("j01", "", "", [dataclasses.replace(f, bias_k=math.nan) for f in result])
    store.save_day(store.begin_run("j01", day), "j01", day, bare)
    build_report(store, tmp_path / "rep", ReportOptions(satellites=["j01"]))
    sat = tmp_path / "rep" / "j01"
    assert "No intercalibration stored" in (sat / "index.html").read_text()
    assert not (sat / "calibration_bins.png").exists() and not (sat / "calibration_trend.png").exists()


def test_years_with_a_step_a_change_and_an_alert(store, tmp_path):
    days = fill_store(store, ["j01"], dt.date(2025, 1, 1), 400, step_day=300)
    AlertState(store).upsert(
        Finding(
            Rule.SPEC, "j01", Severity.CRITICAL, "FOR 30 cross-track 2.5 km over the 1.5 km spec", group="x"
        ),
        dt.datetime(2025, 10, 28, tzinfo=dt.timezone.utc),
        False,
    )
    opts = ReportOptions(satellites=["j01"], calendar=_calendar(tmp_path, days[300]))
    build_report(store, tmp_path / "rep", opts)
    page = (tmp_path / "rep" / "j01" / "index.html").read_text()
    assert (
        "EP V116 uploaded" in page and "FOR 30 cross-track 2.5 km" in page and "out of specification" in page
    )
    assert "400 day(s) shown" in page
    # what the upload did: the 800 urad cross-track step of FORs 21-30, significant there only
    effect = page.split("What each known change did")[1]
    assert "EP V116 uploaded" in effect and effect.count("<tr class=sig>") == 10
    assert all(f"<td>{k}</td><td class=l>cross-track</td>" in effect.split("<tr class=sig>")[k - 20] for k in
               range(21, 31))  # fmt: skip
    summary = json.loads((tmp_path / "rep" / "report.json").read_text())
    assert summary[0]["worst_for"] == 30 and summary[0]["firing"] == 1
    # "worst" as status has it: the larger direction of the worst reliable FOR, not the total
    from monitor.config.file import load_config as _load
    from monitor.service.status import status_report

    status_cfg = tmp_path / "status.yaml"
    status_cfg.write_text(f"satellites: [j01]\nstate_dir: {tmp_path / 'x'}\nsource: {{kind: simulated}}\n")
    assert summary[0]["worst_km"] == status_report(_load(status_cfg), store).satellites[0].worst_km
    latest = store.day_result("j01", days[-1])
    assert summary[0]["worst_km"] < max(f.total_km for f in latest if f.reliable)
    # --since/--until through the command line
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        yaml.safe_dump(
            {
                "satellites": ["j01"],
                "state_dir": str(tmp_path / "st"),
                "source": {"kind": "simulated"},
                "store": {"sqlite": str(tmp_path / "s.sqlite")},
            }
        )
    )
    assert (
        main(
            [
                "report",
                "--config",
                str(cfg),
                "--out",
                str(tmp_path / "r2"),
                "--since",
                "2025-03-01",
                "--until",
                "2025-03-31",
            ]
        )
        == 0
    )
    assert "31 day(s) shown" in (tmp_path / "r2" / "j01" / "index.html").read_text()
    assert main(["report", "--config", str(cfg), "--since", "2025-03-31", "--until", "2025-03-01"]) == 2


@pytest.mark.servers
def test_report_in_headless_chromium(store, tmp_path):
    days = fill_store(store, SATS, dt.date(2025, 6, 1), 120, step_day=90)
    build_report(
        store, tmp_path / "rep", ReportOptions(satellites=SATS, calendar=_calendar(tmp_path, days[90]))
    )
    driver = chromium_driver(tmp_path)
    try:
        for page in ["index.html"] + [f"{s}/index.html" for s in SATS]:
            driver.get((tmp_path / "rep" / page).as_uri())
            images = driver.execute_script(
                "return Array.from(document.images).map(i => [i.src, i.complete, i.naturalWidth]);"
            )
            assert all(ok and width > 0 for _, ok, width in images), images
            if page != "index.html":
                # km, urad, heat map, trend, cost, intercalibration x 2, CrIS minus VIIRS per band x 2 (the
                # synthetic history stores no bins or maps), the offsets in I5 and M15
                assert len(images) == 10
            errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
            assert not errors, errors
        # the page alone, as a mail attachment opens it: every figure is inside it, within the budget
        mailed = tmp_path / "mailed" / "crisgeo-j01.html"
        mailed.parent.mkdir()
        shutil.copy(tmp_path / "rep" / "j01" / "index.html", mailed)
        assert mailed.stat().st_size <= PAGE_BUDGET_BYTES
        driver.get(mailed.as_uri())
        images = driver.execute_script(
            "return Array.from(document.images).map(i => [i.src.slice(0, 22), i.complete, i.naturalWidth]);"
        )
        assert len(images) == 10 and all(
            src == "data:image/png;base64," and ok and width > 0 for src, ok, width in images
        ), images
        shot = tmp_path / "report_j01.png"
        assert driver.save_screenshot(str(shot)) and shot.read_bytes()[:8] == PNG
        # a broken image is noticed: the check above can fail
        mailed.write_text(mailed.read_text().replace("base64,iVBOR", "base64,AAAA", 1))
        driver.get(mailed.as_uri())
        WebDriverWait(driver, 30).until(
            lambda d: d.execute_script("return Array.from(document.images).every(i => i.complete);")
        )
        widths = driver.execute_script("return Array.from(document.images).map(i => i.naturalWidth);")
        assert 0 in widths
    finally:
        driver.quit()
    if os.environ.get("CRISGEO_SCREENSHOT_DIR"):
        shutil.copy(shot, os.environ["CRISGEO_SCREENSHOT_DIR"])


def test_an_alerts_marker_sits_on_the_day_it_started():
    """A spec alert raised by the run of day 2 (it started after that run ended, before day 3's) is marked
    on day 2, however late the report is drawn; a step's alert on the step's date."""
    from monitor.core.vocabulary import AlertStatus, RunStatus
    from monitor.history.records import Alert, Run
    from monitor.service.outputs.report.html import _alert_day

    runs = [
        Run(i, "j01", f"2026-01-0{i}", f"2026-01-0{i + 1}T03:00:00+00:00", f"2026-01-0{i + 1}T03:30:00+00:00",
            RunStatus.OK, None, 3, None)
        for i in (1, 2, 3)
    ]  # fmt: skip

    def alert(rule, started, grp=None):
        return Alert(f"{rule}:j01", rule, "j01", grp, None, AlertStatus.FIRING, started, None, None, "", [])

    assert _alert_day(alert("spec", "2026-01-03T04:00:00+00:00"), runs) == dt.date(2026, 1, 2)
    assert _alert_day(alert("spec", "2026-01-03T03:10:00+00:00"), runs) == dt.date(2026, 1, 1)
    assert _alert_day(alert("jump", "2026-01-04T04:00:00+00:00", "2026-01-02"), runs) == dt.date(2026, 1, 2)
    assert _alert_day(alert("spec", "2026-01-01T00:00:00+00:00"), runs) is None
