"""The scheduler's job events as the service records them: an error, a missed run, a skipped run."""

import datetime as dt

from apscheduler.events import (
    EVENT_JOB_ERROR,
    EVENT_JOB_MAX_INSTANCES,
    JobExecutionEvent,
    JobSubmissionEvent,
)

from monitor.config.file import load_config
from monitor.core.vocabulary import EventKind
from monitor.service.daemon import Service

WHEN = dt.datetime(2024, 6, 2, 6, 0, tzinfo=dt.timezone.utc)


def _service(tmp_path):
    p = tmp_path / "c.yaml"
    p.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        f"alerts: {{log: {tmp_path / 'alerts.log'}}}\n"
    )
    return Service(load_config(p))


def test_a_skipped_run_is_recorded_with_its_run_times(tmp_path):
    """apscheduler reports a run skipped for max_instances as a JobSubmissionEvent: run times, plural."""
    service = _service(tmp_path)
    service._job_event(JobSubmissionEvent(EVENT_JOB_MAX_INSTANCES, "daily-j01", "default", [WHEN]))
    with service.store() as store:
        (event,) = store.events(EventKind.JOB_SKIPPED)
    assert event.satellite == "j01"
    assert event.detail == {"job": "daily-j01", "error": "job_skipped", "scheduled": str(WHEN)}


def test_a_failed_run_is_recorded_with_its_error(tmp_path):
    service = _service(tmp_path)
    failure = JobExecutionEvent(EVENT_JOB_ERROR, "daily-j01", "default", WHEN, exception=OSError("disk gone"))
    service._job_event(failure)
    with service.store() as store:
        (event,) = store.events(EventKind.JOB_ERROR)
    assert event.detail["error"] == "disk gone"
    assert event.detail["scheduled"] == str(WHEN)
