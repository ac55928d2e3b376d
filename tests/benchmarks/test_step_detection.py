"""A reduced run of benchmarks/step_detection.py: the memory path is the store's path, and a step at an
EP upload is found, dated and named (the full figures: studies/rows/step_detection_*.jsonl)."""

import pytest

from benchmarks import step_detection as sd


@pytest.mark.slow  # a year through SQLite and evaluate, ~2 min; tests/alerts/test_rules.py drives a store too
def test_the_memory_path_gives_the_stores_findings():
    assert sd.store_check(1) == 0


def test_a_step_at_an_upload_is_found_within_three_days_and_named():
    trial = sd.detect_trial((sd.Case(120.0, "white", 300.0, "3", 1, "at"), 1))
    assert trial["found"] and trial["delay_days"] <= 2 and abs(trial["date_error_days"]) <= 1
    assert trial["paged"] and trial["names_change"]
    assert max(abs(e) for e in trial["errors"]) < 5.0
