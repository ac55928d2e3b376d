"""The report's CrIS minus VIIRS per VIIRS band (:mod:`monitor.matchup.radiometry`): the latest day against
FOR and against scene temperature, the trend of each band, and one granule's difference map per band with
the FOR edges drawn (the figure the STAR slides show for M15); and the offsets read in M15 beside I5's
(:mod:`monitor.estimation.band_pair`).

The figures take plain arrays and records; :func:`band_section` reads the store and returns the HTML.
"""

from __future__ import annotations

import datetime as dt
import html
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from monitor.core.bands import BANDS
from monitor.core.constants import N_FOR
from monitor.core.result import FLAG_BANDS_DIFFER, SECOND_BAND, DifferenceMap, ForOffset, RadiometryBin
from monitor.core.vocabulary import BinnedBy
from monitor.history.records import ForSeries
from monitor.service.outputs.report import plots
from monitor.service.store.sqlite import Store

COLOURS = {"I5": "tab:blue", "M13": "tab:purple", "M15": "tab:orange", "M16": "tab:green"}
FIGURES = ("band_fors.png", "band_scenes.png", "band_trend.png", "band_maps.png", "band_offsets.png")


def _measured(fors: Sequence[ForOffset]) -> list[str]:
    """The bands with a difference at some FOR."""
    return [b for b in BANDS if any(np.isfinite(getattr(f, f"cris_minus_viirs_k_{b}")) for f in fors)]


def fors_figure(path: Path, fors: Sequence[ForOffset], bands: Sequence[str], title: str) -> Path:
    """Each band's CrIS minus VIIRS against FOR, with its 2-sigma bars.

    Parameters
    ----------
    path : Path
        The PNG to write.
    fors : sequence of ForOffset
        The day's FORs.
    bands : sequence of str
        The bands drawn.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    fig, ax = plt.subplots(figsize=(9, 3.8), constrained_layout=True)
    ax.axhline(0.0, color="0.5", lw=0.8)
    k = np.array([f.for_index for f in fors])
    for i, b in enumerate(bands):
        d = np.array([getattr(f, f"cris_minus_viirs_k_{b}") for f in fors])
        s = np.array([getattr(f, f"sigma_cris_minus_viirs_k_{b}") for f in fors])
        ax.errorbar(k + (i - 1.5) * 0.1, d, yerr=2 * np.nan_to_num(s), fmt="o-", ms=3, capsize=2,
                    color=COLOURS[b], label=b)  # fmt: skip
    ax.set_xlabel("FOR")
    ax.set_ylabel("CrIS - VIIRS BT (K)")
    ax.set_xlim(0.5, N_FOR + 0.5)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=len(bands))
    ax.set_title(title, fontsize=10)
    return plots._save(fig, path)


def offsets_figure(path: Path, fors: Sequence[ForOffset], title: str) -> Path:
    """The offsets read in M15 beside I5's per FOR (2-sigma bars), and M15 minus I5 with the 2-sigma bars of
    the paired jackknife, the FORs flagged ``bands_differ`` ringed.

    Parameters
    ----------
    path : Path
        The PNG to write.
    fors : sequence of ForOffset
        The day's FORs.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    fig, axes = plt.subplots(2, 2, figsize=(10, 5.6), sharex=True, constrained_layout=True)
    k = np.array([f.for_index for f in fors])
    flagged = np.array([FLAG_BANDS_DIFFER in f.flags for f in fors])
    for col, (axis, words) in enumerate((("alpha", "in-track"), ("beta", "cross-track"))):
        top, bottom = axes[0, col], axes[1, col]
        for dx, band, suffix in ((-0.1, "I5", ""), (0.1, SECOND_BAND, f"_{SECOND_BAND}")):
            v = np.array([getattr(f, f"d_{axis}_urad{suffix}") for f in fors])
            s = np.array([getattr(f, f"sigma_{axis}_urad{suffix}") for f in fors])
            top.errorbar(k + dx, v, yerr=2 * np.nan_to_num(s), fmt="o-", ms=3, capsize=2, color=COLOURS[band],
                         label=band)  # fmt: skip
        d = np.array([getattr(f, f"m15_minus_i5_{axis}_urad") for f in fors])
        s = np.array([getattr(f, f"sigma_m15_minus_i5_{axis}_urad") for f in fors])
        bottom.axhline(0.0, color="0.5", lw=0.8)
        bottom.errorbar(k, d, yerr=2 * np.nan_to_num(s), fmt="o", ms=3, capsize=2, color="0.2")
        bottom.scatter(k[flagged], d[flagged], s=70, facecolors="none", edgecolors="tab:red",
                       label="bands_differ")  # fmt: skip
        top.set_title(f"{words} offset (urad)", fontsize=9)
        bottom.set_title(f"{SECOND_BAND} minus I5, {words} (urad)", fontsize=9)
        bottom.set_xlabel("FOR")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
            ax.set_xlim(0.5, N_FOR + 0.5)
        top.legend(fontsize=8)
        if flagged.any():
            bottom.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    return plots._save(fig, path)


def scenes_figure(path: Path, bins: Sequence[RadiometryBin], bands: Sequence[str], title: str) -> Path:
    """Each band's CrIS minus VIIRS against the scene's VIIRS BT (10 K bins), with 2-sigma bars.

    Parameters
    ----------
    path : Path
        The PNG to write.
    bins : sequence of RadiometryBin
        The day's bins (those by scene temperature are drawn).
    bands : sequence of str
        The bands drawn.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    fig, ax = plt.subplots(figsize=(9, 3.8), constrained_layout=True)
    ax.axhline(0.0, color="0.5", lw=0.8)
    for b in bands:
        rows = [r for r in bins if r.band == b and r.by == BinnedBy.SCENE and np.isfinite(r.mean_k)]
        x = np.array([float(r.key) + 5.0 for r in rows])
        ax.errorbar(x, [r.mean_k for r in rows], yerr=[2 * np.nan_to_num(r.sigma_k) for r in rows], fmt="o-",
                    ms=3, capsize=2, color=COLOURS[b], label=b)  # fmt: skip
    ax.set_xlabel("scene VIIRS BT (K), 10 K bins")
    ax.set_ylabel("CrIS - VIIRS BT (K)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=len(bands))
    ax.set_title(title, fontsize=10)
    return plots._save(fig, path)


def trend_figure(
    path: Path, days: Sequence[dt.date], values: dict[str, np.ndarray], changes: plots.Marks, title: str
) -> Path:
    """Each band's daily CrIS minus VIIRS (median over FORs, the band between their quartiles), one panel
    per band, with the known changes.

    Parameters
    ----------
    path : Path
        The PNG to write.
    days : sequence of datetime.date
        The days.
    values : dict
        Band to (days, FORs) differences, K.
    changes : Marks
        Known changes, drawn as lines.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    when = [dt.datetime(d.year, d.month, d.day) for d in days]
    fig, axes = plt.subplots(len(values), 1, figsize=(11, 1.2 + 1.6 * len(values)), sharex=True,
                             constrained_layout=True, squeeze=False)  # fmt: skip
    for ax, (b, v) in zip(axes[:, 0], values.items(), strict=True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # days without the band: NaN
            q1, med, q3 = np.nanpercentile(v, [25, 50, 75], axis=1)
        ax.fill_between(when, q1, q3, color=COLOURS[b], alpha=0.2, lw=0)
        ax.plot(when, med, "-", marker="." if len(when) < 60 else None, color=COLOURS[b], lw=1.2)
        plots._mark_changes(ax, changes, label=False)
        ax.set_ylabel(f"{b} (K)")
        ax.grid(alpha=0.3)
    plots._days_axis(axes[-1, 0], when)
    fig.suptitle(title, fontsize=10)
    return plots._save(fig, path)


def _for_edges(lat: np.ndarray, lon: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Lines between neighbouring FORs: through the midpoints of their centres, scan by scan."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a FOR without FOVs: NaN
        clat, clon = np.nanmean(lat, axis=2), np.nanmean(lon, axis=2)  # (scans, 30)
    return [
        (0.5 * (clon[:, k] + clon[:, k + 1]), 0.5 * (clat[:, k] + clat[:, k + 1])) for k in range(N_FOR - 1)
    ]


def maps_figure(path: Path, maps: Sequence[DifferenceMap], title: str) -> Path:
    """One granule's CrIS minus VIIRS at every FOV, a panel per band, the FOR edges drawn; the FOVs the
    day's difference counts (uniform in VIIRS) ringed.

    Parameters
    ----------
    path : Path
        The PNG to write.
    maps : sequence of DifferenceMap
        One per band.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    fig, axes = plt.subplots(1, len(maps), figsize=(3.4 * len(maps) + 1, 4.2), constrained_layout=True,
                             squeeze=False)  # fmt: skip
    for ax, m in zip(axes[0], maps, strict=True):
        d = m.difference_k
        lim = max(0.5, float(np.nanpercentile(np.abs(d), 95))) if np.isfinite(d).any() else 1.0
        sc = ax.scatter(m.longitude_deg.ravel(), m.latitude_deg.ravel(), c=d.ravel(), s=10, cmap="RdBu_r",
                        vmin=-lim, vmax=lim)  # fmt: skip
        u = m.uniform.ravel()
        ax.scatter(m.longitude_deg.ravel()[u], m.latitude_deg.ravel()[u], s=16, facecolors="none",
                   edgecolors="k", linewidths=0.4)  # fmt: skip
        for x, y in _for_edges(m.latitude_deg, m.longitude_deg):
            ax.plot(x, y, color="0.4", lw=0.5)
        ax.set_title(f"{m.band}: CrIS - VIIRS (K)", fontsize=9)
        ax.set_xlabel("longitude (deg)")
        ax.tick_params(labelsize=7)
        fig.colorbar(sc, ax=ax, shrink=0.8)
    axes[0, 0].set_ylabel("latitude (deg)")
    fig.suptitle(title, fontsize=9)
    return plots._save(fig, path)


def band_section(
    store: Store,
    satellite: str,
    name: str,
    series: ForSeries,
    marks: plots.Marks,
    sat_dir: Path,
    img: Callable[[Path, str], str],
) -> str:
    """The report's section on CrIS minus VIIRS per band; writes its figures into *sat_dir*.

    Parameters
    ----------
    store : Store
        The store.
    satellite : str
        The satellite's short name.
    name : str
        Its name (``NOAA-20``).
    series : ForSeries
        The period's series (every measured field).
    marks : Marks
        The known changes.
    sat_dir : Path
        The satellite's folder of the report.
    img : callable
        How the page embeds a figure (path, alt text) as HTML.

    Returns
    -------
    str
        The section's HTML (a note where no band was compared).
    """
    latest = series.days[-1]
    fors = store.day_result(satellite, latest)
    bands = _measured(fors)
    trend = {
        b: series.values[f"cris_minus_viirs_k_{b}"]
        for b in BANDS
        if np.isfinite(series.values[f"cris_minus_viirs_k_{b}"]).any()
    }
    if not bands and not trend:
        return "<p class=note>No CrIS minus VIIRS per band stored for this period (assessment.bands).</p>"
    out = []
    day = f"{name}, {latest.isoformat()}"
    if bands:
        fors_figure(sat_dir / FIGURES[0], fors, bands, f"{day}: CrIS - VIIRS per FOR, uniform FOVs (2 sigma)")
        out.append(img(sat_dir / FIGURES[0], "CrIS minus VIIRS per band against FOR"))
        bins = store.radiometry_bins(satellite, latest)
        if bins:
            scenes_figure(sat_dir / FIGURES[1], bins, bands, f"{day}: CrIS - VIIRS against scene temperature")
            out.append(img(sat_dir / FIGURES[1], "CrIS minus VIIRS per band against scene temperature"))
    if trend:
        trend_figure(sat_dir / FIGURES[2], series.days, trend, marks, f"{name}: CrIS - VIIRS per band")
        out.append(img(sat_dir / FIGURES[2], "CrIS minus VIIRS per band over time"))
    if any(np.isfinite(f.d_alpha_urad_M15) for f in fors):
        offsets_figure(
            sat_dir / FIGURES[4], fors, f"{day}: the offsets read in I5 and in {SECOND_BAND} (2 sigma)"
        )
        out.append(img(sat_dir / FIGURES[4], f"LOS offsets in I5 and {SECOND_BAND} against FOR"))
    maps = store.difference_maps(satellite, latest)
    if maps:
        granules = ", ".join(sorted({m.granule for m in maps}))
        maps_figure(sat_dir / FIGURES[3], maps, f"{day}: {html.escape(granules)}")
        out.append(img(sat_dir / FIGURES[3], "CrIS minus VIIRS difference map per band"))
    return "".join(out) + (
        "<p class=note>Per band and FOR: CrIS convolved with the band's spectral response minus VIIRS "
        "averaged over the FOV, over the day's FOVs uniform in VIIRS (M13 on scenes above 260 K), on the "
        "assessed geolocation; bars are 2 sigma from the granule jackknife. The map shows every FOV of one "
        "granule, the uniform ones ringed, grey lines the FOR edges. A level beyond "
        "alerts.radiometry_limit_k pages (radiometry), a step pages as a calibration_jump. The offsets "
        f"read in {SECOND_BAND} (where assessment.bands lists it) are assessed as I5's; their difference "
        "has the paired jackknife's sigma (both bands see the same granules), and a FOR where it exceeds 3 "
        "sigmas is flagged bands_differ: VIIRS's band-to-band registration or geolocation, not CrIS's.</p>"
    )
