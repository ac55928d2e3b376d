"""The report's time axes span the data: the days shown, each whole, neither padded nor widened by a change
far back."""

import datetime as dt

import matplotlib.dates as mdates
import numpy as np
import pytest

from monitor.service.outputs.report import plots

DAY = dt.date(2026, 11, 24)


@pytest.fixture
def limits(monkeypatch):
    """The x limits (days) of the bottom axis of every figure saved."""
    seen = []

    def keep(fig, path):
        seen.append(fig.axes[1].get_xlim())
        plots.plt.close(fig)
        return path

    monkeypatch.setattr(plots, "_save", keep)
    return seen


@pytest.mark.parametrize("n_days", [1, 3, 40])
def test_the_axis_spans_the_days_shown_and_no_more(limits, tmp_path, n_days):
    days = [DAY - dt.timedelta(days=n_days - 1 - k) for k in range(n_days)]
    rng = np.random.default_rng(1)
    km = rng.normal(0, 0.5, (n_days, 30))
    changes = [(dt.datetime(2014, 2, 27), "cris", "an old EP")]  # outside the window: must not widen it
    plots.heatmaps(tmp_path / "h.png", days, km, km, 1.5, changes, "t")
    plots.trend_lines(tmp_path / "t.png", days, [1, 15, 30], km, km, 1.5, changes, [], "t")
    plots.calibration_trend(tmp_path / "c.png", days, km, km, changes, "t")
    last = mdates.date2num(dt.datetime.combine(DAY, dt.time(12)))  # days are drawn centred on 00:00
    for x0, x1 in limits:
        assert x1 == pytest.approx(last)  # the last day's end: its column is whole
        assert x1 - x0 == pytest.approx(n_days, abs=1e-6)
