"""/metrics as a registry (the endpoint serves it in test_endpoint.py): the last run's stages come from the
store, so a new process shows them; the standard process and platform collectors come along; text and
OpenMetrics are negotiated as prometheus-client's handler does."""

import datetime as dt

from prometheus_client.exposition import choose_encoder
from prometheus_client.parser import text_string_to_metric_families

from monitor.service.outputs.metrics import ServiceMetrics
from monitor.service.store.sqlite import Store


class _Healthy:
    def problems(self):
        return []


def test_the_last_runs_stages_survive_a_restart_and_the_standard_collectors_are_there(tmp_path):
    path = tmp_path / "s.sqlite"
    with Store(path) as store:
        run = store.begin_run("j01", dt.date(2026, 1, 1))
        store.finish_run(run, "ok")
        store.record_stages(run, {"list": 1.5, "assess": 42.25})
    # a new process: a registry of its own over the same store
    metrics = ServiceMetrics(lambda: Store(path), ["j01", "npp"], _Healthy(), "1.0.0", 1.5)
    encode, content_type = choose_encoder("text/plain")
    fams = {f.name: f for f in text_string_to_metric_families(encode(metrics.registry).decode())}
    stages = {s.labels["stage"]: s.value for s in fams["crisgeo_run_duration_seconds"].samples}
    assert stages == {"list": 1.5, "assess": 42.25}  # npp has run nothing: no series
    assert "process_resident_memory_bytes" in fams or "process_cpu_seconds" in fams
    assert "python_info" in fams and "python_gc_objects_collected" in fams
    assert content_type.startswith("text/plain")
    encode, content_type = choose_encoder("application/openmetrics-text; version=1.0.0")
    body = encode(metrics.registry).decode()
    assert content_type.startswith("application/openmetrics-text") and body.rstrip().endswith("# EOF")
