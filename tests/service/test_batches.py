"""A day assessed in batches until its precision target: every reason to stop, recorded and shown.

The loop is tested with a stand-in estimate whose sigma falls as 1 / sqrt(granules) (the jackknife's law,
measured on real data in docs/science.md), so that no test pays for an assessment; selection, fetching and
the store are real."""

import dataclasses
import time

import pytest
from prometheus_client import generate_latest

from monitor.archive.local import LocalSource
from monitor.assessment.assess import DayAssessment
from monitor.config.file import load_config
from monitor.core.result import DayPrecision
from monitor.core.vocabulary import DayStop
from monitor.service.outputs.metrics import ServiceMetrics
from monitor.service.outputs.report.html import ReportOptions, build_report
from monitor.service.pipeline import run_day
from monitor.service.status import status_report
from monitor.service.store.sqlite import Store
from tests.service.test_pipeline import DAY, TODAY

ONE_GRANULE_URAD = 100.0  # the stand-in's sigma of one granule


def scaled(cases, seconds_per_batch=0.0):
    """A stand-in estimate: the cached case's result with every sigma ONE_GRANULE_URAD / sqrt(granules)."""
    _, _, reference = cases.get()

    class Scaled(DayAssessment):  # the batches, fetching and recording are real; the estimate stands in
        batches: list = []

        def __init__(self, satellite, config, workers):
            super().__init__(satellite, config, workers)
            self.granules = 0

        def add(self, case, *args, **kw):
            time.sleep(seconds_per_batch)
            self.granules += len(case.cris)
            Scaled.batches.append([g.key for g in case.cris])

        def result(self, timings=None):
            sigma = ONE_GRANULE_URAD / self.granules**0.5
            fors = [
                dataclasses.replace(f, sigma_alpha_urad=sigma, sigma_beta_urad=sigma / 2)
                for f in reference.fors
            ]
            return dataclasses.replace(reference, fors=fors)

    return Scaled


class CountingSource(LocalSource):
    """A local tree that counts the bytes of what it hands out, as the NODD source counts its downloads."""

    def fetch(self, f):
        path = super().fetch(f)
        self.spent_bytes += path.stat().st_size
        return path


def run(cases, tmp_path, scenes, budget_mb=6000, budget_min=240, source=LocalSource, seconds_per_batch=0.0):
    data, _, _ = cases.get()
    p = tmp_path / "c.yaml"
    p.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nassessment: {{workers: 1}}\nscenes: {scenes}\n"
        f"source: {{kind: local, path: {data}, daily_budget_mb: {budget_mb}}}\n"
        f"schedule: {{catch_up_days: 3, run_budget_min: {budget_min}}}\n"
    )
    cfg = load_config(p)
    store = Store(cfg.store.sqlite)
    assessor = scaled(cases, seconds_per_batch)
    out = run_day(cfg, store, source(data), "j01", DAY, TODAY, assessor=assessor)
    assert out.status == "ok", out.reason
    return out, store, assessor.batches, cfg


@pytest.mark.parametrize(
    ("scenes", "stop", "granules"),
    [
        ("{keep: 1}", DayStop.ONE_BATCH, 1),  # no target: one batch, as the paper
        ("{keep: 1, target_sigma_urad: 75}", DayStop.TARGET, 2),  # 100 / sqrt(2) = 71
        ("{keep: 1, target_sigma_urad: 100}", DayStop.TARGET, 1),
        ("{keep: 1, target_sigma_urad: 10}", DayStop.CANDIDATES, 2),
        ("{keep: 1, target_sigma_urad: 10, max_granules: 1}", DayStop.MAX_GRANULES, 1),
    ],
)
def test_the_day_stops_for_its_reason(cases, tmp_path, scenes, stop, granules):
    out, store, batches, _ = run(cases, tmp_path, scenes)
    p = out.precision
    assert (p.stop, p.granules, p.batches) == (stop, granules, granules)
    assert [len(b) for b in batches] == [1] * granules
    assert p.sigma_urad == pytest.approx(ONE_GRANULE_URAD / granules**0.5)  # the worse direction
    assert store.latest_precision("j01") == p
    decisions = store.selection("j01", DAY)
    assert [d.decision for d in decisions].count("chosen") == granules
    assert all(str(stop) in d.reason for d in decisions if d.decision == "rejected")


def test_the_batches_take_the_best_first_and_never_twice(cases, tmp_path):
    out, store, batches, _ = run(cases, tmp_path, "{keep: 1, target_sigma_urad: 10}")
    assert len({k for b in batches for k in b}) == 2
    chosen = [d for d in store.selection("j01", DAY) if d.decision == "chosen"]
    chosen.sort(key=lambda d: d.reason.split("rank ")[1])
    assert chosen[0].reason.endswith("rank 1, batch 1") and chosen[0].score_k >= chosen[1].score_k


def test_a_batch_that_would_pass_the_byte_budget_is_not_begun(cases, tmp_path):
    """The first batch's bytes (its CrIS files were read by selection: its VIIRS pair) are the estimate of
    the next; a budget with less room than that left stops the day, which keeps its results."""
    data, _, _ = cases.get()
    cris = sum(f.stat().st_size for f in data.glob("*CRI*.h5")) + sum(
        f.stat().st_size for f in data.glob("GCRSO*.h5")
    )
    viirs = sum(f.stat().st_size for f in data.glob("*.h5")) - cris
    budget_mb = (cris + viirs + viirs / 2) / 1e6  # room for the first batch, not for a second like it
    out, _, batches, _ = run(
        cases,
        tmp_path,
        "{keep: 1, target_sigma_urad: 10}",
        budget_mb=budget_mb,
        source=CountingSource,
    )
    assert (out.precision.stop, out.precision.granules) == (DayStop.BYTES, 1)
    assert out.precision.mb_per_granule == pytest.approx(out.counts.bytes / 1e6 / out.counts.assessed)


def test_a_batch_that_would_pass_the_time_budget_is_not_begun(cases, tmp_path):
    out, _, _, _ = run(
        cases,
        tmp_path,
        "{keep: 1, target_sigma_urad: 10}",
        budget_min=0.02,
        seconds_per_batch=0.7,
    )
    assert (out.precision.stop, out.precision.granules) == (DayStop.TIME, 1)


def test_status_metrics_and_report_show_how_far_the_day_went(cases, tmp_path):
    out, store, _, cfg = run(cases, tmp_path, "{keep: 1, target_sigma_urad: 75}")
    status = status_report(cfg, store)
    assert "precision: 2 granules in 2 batch(es), sigma 71 urad (target 75)" in status.text()
    assert "target reached" in status.text()
    assert status.to_dict()["satellites"]["j01"]["precision"]["stop"] == "target reached"
    metrics = ServiceMetrics(lambda: Store(cfg.store.sqlite), ["j01"], _Healthy(), "test", 1.5)
    text = generate_latest(metrics.registry).decode()
    assert 'crisgeo_day_granules_assessed{satellite="j01"} 2.0' in text
    assert 'crisgeo_day_stop_info{reason="target",satellite="j01"} 1.0' in text
    assert 'crisgeo_day_stop_info{reason="one_batch",satellite="j01"} 0.0' in text
    sigma = float(text.split('crisgeo_day_sigma_radians{satellite="j01"} ')[1].split()[0])
    assert sigma == pytest.approx(ONE_GRANULE_URAD / 2**0.5 * 1e-6)
    build_report(store, tmp_path / "report", ReportOptions(satellites=["j01"]))
    page = (tmp_path / "report" / "j01" / "index.html").read_text()
    assert "Precision of the latest run: 2 granules in 2 batch(es), sigma 71 urad (target 75)" in page


class _Healthy:
    def problems(self):
        return []


def test_a_precision_round_trips_through_the_run_summary():
    p = DayPrecision(24, 2, 61.2, 60.0, DayStop.TIME, 210.0)
    assert DayPrecision.from_summary('{"precision": %s}' % __import__("json").dumps(p.to_dict())) == p
    assert DayPrecision.from_summary('{"reliable_fors": 30}') is None
    assert (
        p.text() == "24 granules in 2 batch(es), sigma 61 urad (target 60), 210 MB per granule: time budget"
    )
