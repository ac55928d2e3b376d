"""The text the commands print: one FOR table for assess, run and status."""

import datetime as dt

from monitor.render import BRIEF, for_table, result_text, status_text
from monitor.simulate.history import day_result


def _result():
    import numpy as np

    return day_result("j01", dt.date(2026, 1, 1), np.random.default_rng(3), 0.0, with_cube=False)


def test_the_full_table_has_a_header_units_and_a_line_per_for():
    result = _result()
    lines = result_text(result).splitlines()
    assert lines[1].split() == [
        "FOR",
        "d_alpha",
        "+-",
        "d_beta",
        "+-",
        "in-trk",
        "x-trk",
        "total",
        "N",
        "G_min",
        "G_0",
        "FWHM",
        "flags",
    ]
    assert lines[2].split() == ["urad", "urad", "km", "km", "km", "K", "K", "urad"]
    rows = lines[3:33]
    assert [int(r.split()[0]) for r in rows] == list(range(1, 31))
    f = result.fors[4]
    assert rows[4].split()[1] == f"{f.d_alpha_urad:.0f}" and rows[4].split()[5] == f"{f.in_track_km:.3f}"


def test_status_shows_the_brief_table_of_stored_values_even_with_gaps():
    """The status report carries FORs as JSON (None where nothing is known): the table still prints."""
    result = _result()
    fors = [f.to_dict() for f in result.fors]
    fors[0]["d_alpha_urad"] = None
    rep = {
        "state": "OK",
        "satellites": {
            "j01": {
                "last_run": {"day": "2026-01-01", "status": "ok", "finished": None, "reason": None},
                "alerts": [],
                "latest_day": "2026-01-01",
                "fors": fors,
            }
        },
        "next_run_utc": "2026-01-02T03:30Z",
        "outbox": 0,
    }
    text = status_text(rep).splitlines()
    header = next(i for i, line in enumerate(text) if line.split()[:1] == ["FOR"])
    assert text[header].split()[:-1] == ["FOR", "d_alpha", "d_beta", "in-trk", "x-trk", "total"]
    assert text[header + 1].split()[1] == "nan" and len(for_table(result.fors, BRIEF)) == 31
    assert text[-2] == "next scheduled run: 2026-01-02 03:30 UTC"
