"""The satellite-day's log fields: set around the work, gone after it."""

import pytest

from monitor.core import logcontext


def test_fields_nest_and_end_with_their_block():
    assert logcontext.fields() == {}
    with logcontext.context(satellite="j01", day="2024-06-01", run_id=None):
        with logcontext.context(run_id=3):
            logcontext.stage("fetch")
            expected = {"satellite": "j01", "day": "2024-06-01", "run_id": 3, "stage": "fetch"}
            assert logcontext.fields() == expected
        assert "stage" not in logcontext.fields() and "run_id" not in logcontext.fields()
    assert logcontext.fields() == {}


def test_a_stage_outside_a_day_is_refused():
    with pytest.raises(RuntimeError, match="outside"):
        logcontext.stage("fetch")
