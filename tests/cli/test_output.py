"""The text the commands print: one FOR table for assess, run and status."""

import datetime as dt

from monitor.cli.output import result_text
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
