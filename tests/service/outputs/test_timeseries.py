"""Publishing against real servers on loopback: VictoriaMetrics (v2 write API) and InfluxDB 1.x (/write)."""

import dataclasses
import datetime as dt

import pytest

from benchmarks.servers import free_port, influxdb1, influxql, victoria_metrics, vm_export, wait_for
from monitor.config.outputs import PublishConfig
from monitor.service.outputs.timeseries import (
    Influx2Writer,
    PublishError,
    day_lines,
    drain_outbox,
    result_lines,
    target_name,
)
from monitor.service.store.sqlite import Store

DAY = dt.date(2024, 6, 1)


def _queue(store, cfg, result, day=DAY):
    run = store.begin_run("j01", day)
    store.save_day(run, "j01", day, result, [], day_lines([cfg], "j01", day, result))


def test_lines_have_fixed_types_and_skip_non_finite(cases):
    _, _, result = cases.get()
    f = result.fors[0]
    broken = type(f)(**{**f.__dict__, "sigma_alpha_urad": float("nan")})
    (line,) = result_lines("m", "j01", DAY, [broken])
    assert line.startswith("m,for=01,satellite=j01 ") and "sigma_alpha_urad" not in line
    assert "n_samples=72i" in line and "reliable=true" in line and line.endswith(" 1717200000")


def test_a_band_s_fields_go_to_their_own_points_with_a_band_tag(cases):
    _, _, result = cases.get()
    f = dataclasses.replace(result.fors[0], cris_minus_viirs_k_M15=0.12, sigma_cris_minus_viirs_k_M15=0.01)
    main, band = result_lines("m", "j01", DAY, [f])
    assert "cris_minus_viirs" not in main
    assert band.startswith("m_band,band=M15,for=01,satellite=j01 ") and band.endswith(" 1717200000")
    assert "cris_minus_viirs_k=0.12" in band and "sigma_cris_minus_viirs_k=0.01" in band


@pytest.mark.servers
def test_victoria_metrics_receives_influxdb_client_writes(cases, tmp_path):
    _, _, result = cases.get()
    with victoria_metrics(tmp_path / "vm") as url:
        cfg = PublishConfig(kind="influx2", url=url, bucket="crisgeo")
        store = Store(tmp_path / "s.sqlite")
        _queue(store, cfg, result)
        assert drain_outbox(store, [cfg]) == {target_name(cfg): (30, 0)}
        series = vm_export(url, "cris_geolocation_d_beta_urad")
        assert len(series) == 30
        got = {s["metric"]["for"]: s["values"] for s in series}
        assert all(len(v) == 1 for v in got.values())
        assert got["30"][0] == pytest.approx(result.fors[29].d_beta_urad)
        assert series[0]["timestamps"][0] == 1717200000000


@pytest.mark.servers
def test_influxdb1_over_write_endpoint_read_back_with_influxql(cases, tmp_path):
    _, _, result = cases.get()
    with influxdb1(tmp_path / "influx") as url:
        cfg = PublishConfig(kind="influx1", url=url, database="crisgeo")
        store = Store(tmp_path / "s.sqlite")
        _queue(store, cfg, result)
        assert drain_outbox(store, [cfg])[target_name(cfg)] == (30, 0)
        rows = influxql(
            url,
            "crisgeo",
            'SELECT "cross_track_km", "n_samples" FROM "cris_geolocation" WHERE "for" = \'30\'',
        )[0]["values"]
        assert len(rows) == 1 and rows[0][0] == 1717200000
        assert rows[0][1] == pytest.approx(result.fors[29].cross_track_km) and rows[0][2] == 72
        # the v2 API is missing on InfluxDB 1.6: the client's 404 is a PublishError, not a crash
        with pytest.raises(PublishError, match="404"):
            Influx2Writer(PublishConfig(kind="influx2", url=url)).write(["m f=1 1"])


@pytest.mark.servers
def test_server_down_then_up_nothing_lost_nothing_twice(cases, tmp_path):
    _, _, result = cases.get()
    port = free_port()
    cfg = PublishConfig(kind="influx2", url=f"http://127.0.0.1:{port}", timeout_s=2)
    store = Store(tmp_path / "s.sqlite")
    _queue(store, cfg, result, DAY)
    assert drain_outbox(store, [cfg])[target_name(cfg)] == (0, 30)  # down: points wait
    error = store.outbox_errors(target_name(cfg))[0]
    assert error.startswith(f"http://127.0.0.1:{port}: ") and "Error" in error
    _queue(store, cfg, result, DAY + dt.timedelta(days=1))
    with victoria_metrics(tmp_path / "vm", port) as url:
        assert drain_outbox(store, [cfg])[target_name(cfg)] == (60, 0)
        assert drain_outbox(store, [cfg])[target_name(cfg)] == (0, 0)
        series = vm_export(url, "cris_geolocation_total_km")
        assert len(series) == 30 and all(len(s["values"]) == 2 for s in series)


@pytest.mark.servers
def test_known_changes_reach_influxdb_for_annotations(tmp_path):
    from monitor.config.file import load_config
    from monitor.service.pipeline import publish_changes

    (tmp_path / "events.yaml").write_text(
        "events:\n  - {time: '2024-05-20T08:00:00Z', satellite: j01, instrument: viirs, kind: lut_change,\n"
        "     description: VIIRS-SDR-GEO-IMG-PARAM-LUT update}\n"
    )
    with influxdb1(tmp_path / "influx") as url:
        (tmp_path / "c.yaml").write_text(
            f"satellites: [j01]\nstate_dir: {tmp_path / 'st'}\nsource: {{kind: simulated}}\n"
            f"store: {{publish: [{{kind: influx1, url: '{url}', database: crisgeo}}]}}\n"
            "alerts: {events_file: events.yaml}\n"
        )
        cfg = load_config(tmp_path / "c.yaml")
        store = Store(cfg.store.sqlite)
        publish_changes(cfg, store, "j01")
        publish_changes(cfg, store, "j01")  # re-sent after every run: overwrites, never duplicates
        assert drain_outbox(store, cfg.store.publish)[target_name(cfg.store.publish[0])] == (2, 0)
        (series,) = influxql(
            url, "crisgeo", 'SELECT "description", "instrument" FROM "cris_geolocation_change"'
        )
        assert series["values"] == [[1716192000, "VIIRS-SDR-GEO-IMG-PARAM-LUT update", "viirs"]]


@pytest.mark.servers
def test_the_daemon_drains_the_outbox_on_its_own_timer(cases, tmp_path):
    """Points that waited through an outage leave without a daily run: the daemon's outbox job sends them
    as soon as the server is back."""

    from apscheduler.schedulers.background import BackgroundScheduler

    from monitor.config.file import load_config
    from monitor.service.daemon import Service

    _, _, result = cases.get()
    with victoria_metrics(tmp_path / "vm") as url:
        cfg_file = tmp_path / "c.yaml"
        cfg_file.write_text(
            f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: "
            f"{tmp_path}}}\nstore: {{drain_minutes: 0.02, publish: [{{kind: influx2, url: '{url}', "
            f"bucket: crisgeo}}]}}\n"
        )
        service = Service(load_config(cfg_file))
        store = service.store()
        _queue(store, service.cfg.store.publish[0], result)
        scheduler = BackgroundScheduler(timezone="UTC")
        service.add_jobs(scheduler)
        for job in scheduler.get_jobs():
            if job.id != "outbox":  # no daily run, no alert evaluation: only the timer
                job.remove()
        scheduler.start()
        try:
            wait_for(lambda: store.outbox_size(target_name(service.cfg.store.publish[0])) == 0, 30)
        finally:
            scheduler.shutdown(wait=True)
        assert store.outbox_size(target_name(service.cfg.store.publish[0])) == 0
        assert len(vm_export(url, "cris_geolocation_d_beta_urad")) == 30
        assert not store.runs("j01") or all(r.status != "ok" or r.day == str(DAY) for r in store.runs("j01"))


@pytest.mark.servers
def test_a_rerun_day_keeps_one_value_per_series_with_dedup(cases, tmp_path):
    """Re-running a day queues the same points again (same series, same timestamps). InfluxDB overwrites
    a point with the same series and time; VictoriaMetrics keeps one only with deduplication on
    (``-dedup.minScrapeInterval``, README), which this test starts it with."""
    _, _, result = cases.get()
    with victoria_metrics(tmp_path / "vm", flags=["-dedup.minScrapeInterval=1ms"]) as url:
        cfg = PublishConfig(kind="influx2", url=url, bucket="crisgeo")
        store = Store(tmp_path / "s.sqlite")
        first = []
        for _ in range(2):  # the day, then the same day again
            _queue(store, cfg, result)
            first.append(list(r["line"] for r in store.outbox(target_name(cfg), 100)))
            assert drain_outbox(store, [cfg]) == {target_name(cfg): (30, 0)}
        assert first[0] == first[1]  # the same series and timestamps
        series = vm_export(url, "cris_geolocation_d_alpha_urad")
        assert len(series) == 30 and all(len(s["values"]) == 1 for s in series)
