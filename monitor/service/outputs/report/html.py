"""The self-contained HTML trend report: one page per satellite plus an index. Each page carries its figures
(data: URIs), so ``<sat>/index.html`` alone can be mailed or opened from an attachment; the figures are
written beside it as well.

Layout of the output directory (the alert messages link ``<sat>/index.html`` and attach
``<sat>/trend.png``)::

    index.html               every satellite: latest day, worst FOR, firing alerts
    <sat>/index.html         the page: figures and tables
    <sat>/latest_km.png      figure 8: per-FOR km with the spec band
    <sat>/latest_urad.png    figure 7: per-FOR urad with a % of FOV axis
    <sat>/heatmap.png        FOR x day heat maps, change markers
    <sat>/trend.png          chosen FORs over time, spec band, changes and alerts
    <sat>/cost.png           figure 5c: the cost surface of the latest run's worst FOR

The pages use no script, font, style sheet or image from elsewhere: they open from disk, or from a mail.
"""

from __future__ import annotations

import base64
import datetime as dt
import html
import json
import logging
import os
import tempfile
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from alerts.effects import EFFECT_COLUMNS, ChangeEffect, change_effects
from monitor.config.alert_settings import RuleSettings
from monitor.config.model import Config
from monitor.core.constants import CALIBRATION_BIN_K, CALIBRATION_REFERENCE_K, SPEC_KM
from monitor.core.result import RELIABILITY_FLAGS, DayPrecision, ForOffset, worst_for
from monitor.core.satellites import SATELLITES
from monitor.core.tables import FOR_COLUMNS, REPORT
from monitor.core.vocabulary import DEFAULT_COST, Cost, Rule, RunStatus
from monitor.history.changes import Change, all_changes
from monitor.history.records import Alert, Attachment, ForSeries, Run
from monitor.service.outputs.report import per_band, plots
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store

UTC = dt.timezone.utc
LOG = logging.getLogger(__name__)
# a satellite's page with its figures inside stays well under this for a year and more (docs/operations.md,
# "The HTML report"); mail servers commonly take 10 MB and more
PAGE_BUDGET_BYTES = 1_000_000
CSS = """
body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;margin:1.5em auto;max-width:1100px;color:#222}
h1{font-size:1.5em}h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0}td,th{border:1px solid #ddd;padding:2px
7px;text-align:right}
th{background:#f3f3f3}td.l,th.l{text-align:left}tr.out td{background:#fde2e1}tr.flag td{color:#999}
tr.sig td{font-weight:bold}
img{max-width:100%;border:1px solid #eee;margin:0.3em 0}.note{color:#666;font-size:0.85em}
.ok{color:#1a7f37}.bad{color:#c62828;font-weight:bold}
"""


@dataclass
class ReportOptions:
    """What the report shows: satellites, period, calendar, specification, FORs over time, and the alert
    rules' windows a change's effect is measured over."""

    spec_km: float = SPEC_KM
    rules: RuleSettings = field(default_factory=RuleSettings)
    trend_fors: tuple = (1, 15, 30)
    since: dt.date | None = None
    until: dt.date | None = None
    calendar: Path | None = None
    satellites: list = field(default_factory=list)
    cost: Cost = DEFAULT_COST  # the configured assessment's cost, which the cost surface shows


def options_from_config(
    cfg: Config,
    satellites: Iterable[str] | None = None,
    since: dt.date | None = None,
    until: dt.date | None = None,
) -> ReportOptions:
    """Report options of a service configuration: the spec and windows of its alert rules, its events
    calendar.

    Parameters
    ----------
    cfg : Config
        The configuration.
    satellites : iterable of str, optional
        The satellites; the configured ones by default.
    since, until : datetime.date, optional
        The first and last day, inclusive; None: open.

    Returns
    -------
    ReportOptions
        The options.
    """
    return ReportOptions(
        spec_km=cfg.alerts.spec_km,
        rules=cfg.alerts,
        since=since,
        until=until,
        calendar=cfg.events_file,
        satellites=list(satellites or cfg.satellites),
        cost=cfg.assessment.cost,
    )


def _e(x: object) -> str:
    return html.escape(str(x))


def _write(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.part")
    tmp.write_text(text)
    os.replace(tmp, path)


def _page(title: str, body: str) -> str:
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{_e(title)}</title>'
        '<link rel="icon" href="data:,">'  # no favicon request (a 404 in the browser console)
        f"<style>{CSS}</style></head><body>\n{body}\n</body></html>\n"
    )


def _latest_table(fors: Iterable[ForOffset], spec_km: float) -> str:
    """The latest day's FOR table (the columns of :data:`monitor.core.tables.REPORT`); unreliable FORs greyed,
    FORs beyond the specification marked."""
    cols = [FOR_COLUMNS[c] for c in REPORT]
    head = "".join(
        f"<th{' class=l' if c.align == '<' else ''}>{_e(f'{c.header} {c.unit}'.strip())}</th>" for c in cols
    )
    rows = []
    for f in fors:
        cls = "flag" if not f.reliable else "out" if f.spec_breaches(spec_km) else ""
        cells = "".join(
            f"<td{' class=l' if c.align == '<' else ''}>{_e(_blank_nan(c.text(f)))}</td>" for c in cols
        )
        rows.append(f"<tr class='{cls}'>{cells}</tr>")
    return f"<table><tr>{head}</tr>{''.join(rows)}</table>"


def _blank_nan(text: str) -> str:
    return "" if text in ("nan", "-nan") else text


def _alerts_table(rows: Sequence[Alert]) -> str:
    if not rows:
        return "<p class=ok>No alert is firing.</p>"
    body = "".join(
        f"<tr><td class=l>{_e(r.severity or '')}</td><td class=l>{_e(r.rule)}</td>"
        f"<td class=l>{_e(r.started)}</td><td class=l>{_e(r.summary)}</td></tr>"
        for r in rows
    )
    head = "".join(f"<th class=l>{h}</th>" for h in ("severity", "rule", "since", "summary"))
    return f"<table><tr>{head}</tr>{body}</table>"


def _changes_table(changes: Sequence[Change]) -> str:
    if not changes:
        return "<p class=note>No change known (calendar, granule metadata, LOS fingerprint).</p>"
    body = "".join(
        f"<tr><td class=l>{c.time:%Y-%m-%d %H:%M}</td><td class=l>{_e(c.instrument)}</td>"
        f"<td class=l>{_e(c.kind)}</td><td class=l>{_e(c.description)}</td><td "
        f"class=l>{_e(c.origin)}</td></tr>"
        for c in reversed(changes)
    )
    return (
        "<table><tr><th class=l>time (UTC)</th><th class=l>instrument</th><th class=l>kind</th>"
        f"<th class=l>description</th><th class=l>origin</th></tr>{body}</table>"
    )


def _effects_section(effects: Sequence[ChangeEffect]) -> str:
    """What each known change did (:mod:`alerts.effects`): per change its summary and a table per FOR and
    direction, significant moves in bold."""
    if not effects:
        return "<p class=note>No known change with assessed days on both sides in this period.</p>"
    parts = []
    for e in reversed(effects):
        columns = EFFECT_COLUMNS if e.predicted_urad is not None else EFFECT_COLUMNS[:-2]
        head = "".join(
            f"<th{' class=l' if c.align == '<' else ''}>{_e(f'{c.header} {c.unit}'.strip())}</th>"
            for c in columns
        )
        rows = "".join(
            f"<tr{' class=sig' if r.significant else ''}>"
            + "".join(
                f"<td{' class=l' if c.align == '<' else ''}>{_e(_blank_nan(c.text(r)))}</td>" for c in columns
            )
            + "</tr>"
            for r in e.rows()
        )
        parts.append(f"<h3>{_e(e.title())}</h3><p>{_e(e.summary())}.</p><table><tr>{head}</tr>{rows}</table>")
    return "".join(parts)


def _alert_day(alert: Alert, runs: Sequence[Run]) -> dt.date | None:
    """The day an alert started on, in the data: a step's date (its group), else the latest day whose run
    had ended successfully when it started (the day whose result raised it); None before any."""
    if alert.rule in (Rule.JUMP, Rule.CALIBRATION_JUMP) and alert.grp:
        return dt.date.fromisoformat(alert.grp)
    ended = [
        r for r in runs if r.status == RunStatus.OK and r.finished and r.finished <= (alert.started or "")
    ]
    return max((dt.date.fromisoformat(r.day) for r in ended), default=None)


def _img(path: Path, alt: str) -> str:
    """The figure at *path* inside the page (a data: URI): the page alone carries it, so it can be mailed;
    the file stays beside it for the e-mail's attachment and the dashboard's link."""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{_e(alt)}" title="{_e(path.name)}">'


def _precision(p: DayPrecision | None) -> str:
    """The latest run's precision: granules assessed, the sigma reached against its target, why it
    stopped (scenes.target_sigma_urad)."""
    if p is None:
        return ""
    return f"<p>Precision of the latest run: {_e(p.text())}.</p>"


def _in_period(changes: Iterable[Change], opts: ReportOptions) -> list[Change]:
    """The known changes within the report's period."""
    return [
        c
        for c in changes
        if (opts.since is None or c.time.date() >= opts.since)
        and (opts.until is None or c.time.date() <= opts.until)
    ]


def satellite_page(store: Store, satellite: str, out: Path, opts: ReportOptions) -> dict:
    """Write ``out/<satellite>/`` and return a summary for the index.

    Parameters
    ----------
    store : Store
        The store.
    satellite : str
        The satellite's short name.
    out : Path
        The report's directory.
    opts : ReportOptions
        The options.

    Returns
    -------
    dict
        The page's summary for the index.
    """
    sat_dir = out / satellite
    sat_dir.mkdir(parents=True, exist_ok=True)
    name = f"{SATELLITES[satellite].name if satellite in SATELLITES else satellite} ({satellite})"
    series = store.series(satellite, opts.since, opts.until)
    known = all_changes(store, satellite, opts.calendar)
    changes = _in_period(known, opts)
    state = AlertState(store)
    firing = state.firing(satellite)
    alerts = [a for a in state.all() if a.satellite == satellite and a.started]
    parts = [
        '<p><a href="../index.html">all satellites</a></p><h1>CrIS geolocation against VIIRS I5: '
        f"{_e(name)}</h1>"
    ]
    summary: dict[str, Any] = {
        "satellite": satellite,
        "name": name,
        "latest": None,
        "worst_km": None,
        "firing": len(firing),
        "days": 0,
    }
    if not len(series):
        parts.append("<p>No assessment in the store for this period yet.</p>")
        parts.append("<h2>Active alerts</h2>" + _alerts_table(firing))
        parts.append("<h2>Known changes</h2>" + _changes_table(changes))
        _write(sat_dir / "index.html", _page(f"crisgeo {name}", "\n".join(parts)))
        _drop_figures_except(sat_dir, set())
        return summary
    days, arrays = series.days, series.values
    latest = days[-1]
    fors = store.day_result(satellite, latest)
    reliable = [f.reliable for f in fors]
    col = lambda k: np.array([getattr(f, k) for f in fors], float)  # noqa: E731
    worst = worst_for(fors)
    summary.update(
        latest=latest.isoformat(),
        days=len(days),
        worst_km=None if worst is None else worst.worst_km,
        worst_for=None if worst is None else worst.for_index,
    )
    title = f"{name}, {latest.isoformat()}"
    plots.latest_km(
        sat_dir / "latest_km.png",
        col("in_track_km"),
        col("cross_track_km"),
        col("sigma_in_track_km"),
        col("sigma_cross_track_km"),
        reliable,
        opts.spec_km,
        title,
    )
    plots.latest_urad(
        sat_dir / "latest_urad.png",
        col("d_alpha_urad"),
        col("d_beta_urad"),
        col("sigma_alpha_urad"),
        col("sigma_beta_urad"),
        title,
    )
    marks = [(c.time.replace(tzinfo=None), c.instrument, c.description) for c in changes]
    span = f"{name}, {days[0].isoformat()} .. {latest.isoformat()} ({len(days)} days)"
    plots.heatmaps(
        sat_dir / "heatmap.png",
        days,
        arrays["in_track_km"],
        arrays["cross_track_km"],
        opts.spec_km,
        marks,
        span,
    )
    _trend(store, satellite, series, marks, alerts, opts, span, sat_dir / "trend.png")
    calibration_html = _calibration(store, satellite, name, series, marks, span, sat_dir)
    bands_html = per_band.band_section(store, satellite, name, series, marks, sat_dir, _img)
    stored = store.cost_cube(satellite, latest)
    cost_html = "<p class=note>No cost cube stored for the latest run.</p>"
    figures = {"latest_km.png", "latest_urad.png", "heatmap.png", "trend.png"}
    figures |= {f for f in ("calibration_bins.png", "calibration_trend.png") if f in calibration_html}
    figures |= {f for f in per_band.FIGURES if f in bands_html}
    if stored is not None and worst is not None:
        cube, step = stored
        runs = [r for r in store.runs(satellite) if r.day == latest.isoformat() and r.status == RunStatus.OK]
        plots.cost_contour(
            sat_dir / "cost.png",
            np.asarray(cube[worst.for_index - 1], float),
            worst.for_index,
            step,
            worst.d_alpha_urad,
            worst.d_beta_urad,
            opts.cost,
            f"{title}: worst FOR {worst.for_index}, "
            f"{worst.worst_km:.2f} km" + (f" (run {runs[-1].id})" if runs else ""),
        )
        figures.add("cost.png")
        cost_html = (
            _img(sat_dir / "cost.png", f"cost surface of FOR {worst.for_index}")
            + f"<p class=note>G_min {worst.cost_min_k:.3f} K against {worst.cost_zero_k:.3f} K as "
            "geolocated; "
            "a sharp, closed minimum is a trustworthy result, a flat or open one is flagged.</p>"
        )
    status = (
        "<span class=bad>out of specification</span>"
        if any(f.spec_breaches(opts.spec_km) for f in fors)
        else "<span class=ok>within specification</span>"
    )
    flagged = [f.for_index for f in fors if any(x in RELIABILITY_FLAGS for x in f.flags)]
    parts += [
        f"<p>Latest day {latest.isoformat()}: {status}; worst reliable FOR "
        f"{'-' if worst is None else worst.for_index} at "
        f"{'-' if worst is None else format(worst.worst_km, '.2f')} km in-track or cross-track "
        f"(spec {opts.spec_km:g} km). {len(days)} day(s) shown. Flagged FORs: "
        f"{', '.join(map(str, flagged)) or 'none'}.</p>",
        _precision(store.latest_precision(satellite)),
        "<h2>Active alerts</h2>" + _alerts_table(firing),
        "<h2>Latest per-FOR offsets</h2>"
        + _img(sat_dir / "latest_km.png", "per-FOR km")
        + _img(sat_dir / "latest_urad.png", "per-FOR urad"),
        "<h2>Over time</h2>"
        + _img(sat_dir / "heatmap.png", "FOR x day heat maps")
        + _img(sat_dir / "trend.png", "chosen FORs over time"),
        "<p class=note>Dotted vertical lines: known changes (purple CrIS, green VIIRS, brown common); "
        "red triangles: alerts.</p>",
        "<h2>Cost surface of the worst FOR</h2>" + cost_html,
        "<h2>CrIS-VIIRS intercalibration</h2>" + calibration_html,
        "<h2>CrIS minus VIIRS per band</h2>" + bands_html,
        "<h2>Latest values</h2>" + _latest_table(fors, opts.spec_km),
        "<h2>Known changes</h2>" + _changes_table(changes),
        "<h2>What each known change did</h2><p class=note>Per FOR and direction: the offsets over the "
        f"{opts.rules.pre_days} days before the change and the {opts.rules.post_days} after it (other "
        "changes and the change's own day left out), the move with its sigma in urad and km, whether it is "
        "significant, and where the LOS fingerprints name both EPs the move their mapping angles predict "
        "(crisgeo events effects).</p>"
        + _effects_section(
            [e for e in change_effects(store, satellite, known, opts.rules) if set(e.changes) & set(changes)]
        ),
        f"<p class=note>Generated {dt.datetime.now(UTC):%Y-%m-%d %H:%M} UTC by crisgeo report.</p>",
    ]
    page = _page(f"crisgeo {name}", "\n".join(parts))
    if len(page) > PAGE_BUDGET_BYTES:
        LOG.warning("%s: %d kB, beyond the %d kB a mail may carry", sat_dir / "index.html", len(page) // 1000,
                    PAGE_BUDGET_BYTES // 1000)  # fmt: skip
    _write(sat_dir / "index.html", page)
    _drop_figures_except(sat_dir, figures)
    return summary


def _calibration(
    store: Store,
    satellite: str,
    name: str,
    series: ForSeries,
    marks: list[tuple[dt.datetime, str, str]],
    span: str,
    sat_dir: Path,
) -> str:
    """The intercalibration section: the latest day's CrIS - VIIRS against the CrIS BT (the paper's
    Figure 15) and the bias and gain over time; what is shown, as HTML."""
    out = []
    latest = series.days[-1]
    bins = store.difference_bins(satellite, latest)
    if bins:
        plots.calibration_bins(
            sat_dir / "calibration_bins.png",
            [b.low_k for b in bins],
            [b.n for b in bins],
            [b.mean_k for b in bins],
            [b.std_k for b in bins],
            CALIBRATION_BIN_K,
            f"{name}, {latest.isoformat()}: CrIS - VIIRS I5 at the optimum, all refined FORs",
        )
        out.append(_img(sat_dir / "calibration_bins.png", "CrIS minus VIIRS against CrIS BT"))
    reliable = series.reliable()
    bias = np.where(reliable, series.values["bias_k"], np.nan)
    if np.isfinite(bias).any():
        plots.calibration_trend(
            sat_dir / "calibration_trend.png",
            series.days,
            bias,
            np.where(reliable, series.values["gain_pct"], np.nan),
            marks,
            span,
        )
        out.append(_img(sat_dir / "calibration_trend.png", "CrIS minus VIIRS bias and gain over time"))
    if not out:
        return "<p class=note>No intercalibration stored for this period (assessed before it was kept).</p>"
    return "".join(out) + (
        f"<p class=note>At each FOR's optimum: CrIS - VIIRS = bias + gain (VIIRS BT - "
        f"{CALIBRATION_REFERENCE_K:g} K), fitted over the FOR's samples; the trend shows the median over "
        "the reliable FORs and their quartiles. A step fires the calibration_jump alert.</p>"
    )


def _trend(
    store: Store,
    satellite: str,
    series: ForSeries,
    marks: plots.Marks,
    alerts: Sequence[Alert],
    opts: ReportOptions,
    span: str,
    path: Path,
) -> Path:
    """``trend.png``: the chosen FORs over the period, with the known changes and the days alerts started."""
    days = series.days
    started = [_alert_day(a, store.runs(satellite)) for a in alerts]
    alert_days = sorted(
        {dt.datetime.combine(d, dt.time()) for d in started if d is not None and days[0] <= d <= days[-1]}
    )
    return plots.trend_lines(
        path,
        days,
        opts.trend_fors,
        series.values["in_track_km"],
        series.values["cross_track_km"],
        opts.spec_km,
        marks,
        alert_days,
        span,
    )


def trend_attachment(store: Store, satellite: str, opts: ReportOptions) -> tuple[Attachment, ...]:
    """The report's trend plot of *satellite* as an alert e-mail attaches it (none without data): drawn from
    the store as it stands, so an alert that has just started is marked on it.

    Parameters
    ----------
    store : Store
        The store.
    satellite : str
        The satellite's short name.
    opts : ReportOptions
        The report's options (its period, its chosen FORs).

    Returns
    -------
    tuple of Attachment
        ``trend.png``, or nothing.
    """
    series = store.series(satellite, opts.since, opts.until)
    if not len(series):
        return ()
    name = f"{SATELLITES[satellite].name if satellite in SATELLITES else satellite} ({satellite})"
    changes = _in_period(all_changes(store, satellite, opts.calendar), opts)
    marks = [(c.time.replace(tzinfo=None), c.instrument, c.description) for c in changes]
    alerts = [a for a in AlertState(store).all() if a.satellite == satellite and a.started]
    span = f"{name}, {series.days[0].isoformat()} .. {series.days[-1].isoformat()} ({len(series)} days)"
    with tempfile.TemporaryDirectory(prefix="crisgeo-trend-") as tmp:
        path = _trend(store, satellite, series, marks, alerts, opts, span, Path(tmp) / "trend.png")
        return (Attachment("trend.png", path.read_bytes(), "image/png"),)


def _drop_figures_except(sat_dir: Path, keep: set) -> None:
    """Remove figures of an earlier report that this one no longer shows. Figures are replaced in place,
    never removed first, so a page being read while the report is rewritten keeps its images."""
    for old in sat_dir.glob("*.png"):
        if old.name not in keep:
            old.unlink(missing_ok=True)


def build_report(store: Store, out_dir: str | os.PathLike[str], opts: ReportOptions) -> Path:
    """Write the report for *opts.satellites* into *out_dir*; returns the index path.

    Pages are written under temporary names and moved into place, so a reader never sees half a page.

    Parameters
    ----------
    store : Store
        The store.
    out_dir : str or os.PathLike
        The report's directory.
    opts : ReportOptions
        The options.

    Returns
    -------
    Path
        The index page.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    summaries = [satellite_page(store, sat, out, opts) for sat in opts.satellites]
    rows = "".join(
        f'<tr><td class=l><a href="{s["satellite"]}/index.html">{_e(s["name"])}</a></td>'
        f"<td class=l>{s['latest'] or 'no data'}</td><td>{s['days']}</td>"
        f"<td>{'' if s['worst_km'] is None else format(s['worst_km'], '.2f')}</td>"
        f"<td class={'bad' if s['firing'] else 'ok'}>{s['firing']}</td></tr>"
        for s in summaries
    )
    body = (
        "<h1>crisgeo-monitor: CrIS geolocation against VIIRS</h1>"
        "<table><tr><th class=l>satellite</th><th class=l>latest day</th><th>days</th>"
        f"<th>worst km (in- or cross-track)</th><th>firing alerts</th></tr>{rows}</table>"
        f"<p class=note>Specification {opts.spec_km:g} km. Generated {dt.datetime.now(UTC):%Y-%m-%d %H:%M} "
        "UTC.</p>"
    )
    _write(out / "index.html", _page("crisgeo-monitor report", body))
    _write(out / "report.json", json.dumps(summaries, indent=1, default=str))
    return out / "index.html"
