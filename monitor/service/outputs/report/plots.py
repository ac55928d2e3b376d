"""The report's figures (matplotlib, Agg): the paper's figures 5c, 7, 8 and 15, and their evolution over time.

Every function takes plain arrays and writes one PNG; none reads the store.
"""

from __future__ import annotations

import datetime as dt
import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.dates as mdates  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from numpy.typing import ArrayLike  # noqa: E402

from monitor.core.constants import FOV_DIAMETER_URAD, N_FOR  # noqa: E402
from monitor.core.vocabulary import Cost  # noqa: E402

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

PathLike = str | os.PathLike[str]
Marks = Sequence[tuple[dt.datetime, str, str]]  # known changes: (time, instrument, description)

FORS = np.arange(1, N_FOR + 1)
DPI = 90
CHANGE_COLOURS = {"cris": "tab:purple", "viirs": "tab:green", "common": "tab:brown"}


# the colour bar of the cost surface: the paper's equation (8), or the residual of the regression the
# service minimises by default (docs/science.md, "Cost and minimum")
COST_LABEL = {
    Cost.STDEV: "G = STDEV(BT_VIIRS - BT_CrIS) (K)",
    Cost.REGRESSION: "G = residual STDEV of BT_VIIRS - BT_CrIS regressed on BT_CrIS (K)",
}


def _save(fig: Figure, path: Path) -> Path:
    """Write the figure as PNG through a temporary name: the served report never shows half an image."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.part")
    fig.savefig(tmp, dpi=DPI, format="png")
    plt.close(fig)
    os.replace(tmp, path)
    return path


def latest_km(
    path: PathLike,
    in_track_km: ArrayLike,
    cross_track_km: ArrayLike,
    sigma_in_km: ArrayLike,
    sigma_cross_km: ArrayLike,
    reliable: ArrayLike,
    spec_km: float,
    title: str,
) -> Path:
    """Per-FOR offsets on the ground with 1-sigma bars and the +-spec band (Wang et al. 2017 figure 8).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    in_track_km, cross_track_km : array_like
        Per FOR, km.
    sigma_in_km, sigma_cross_km : array_like
        Their sigmas, km.
    reliable : array_like
        bool per FOR.
    spec_km : float
        The specification, km.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.6), sharey=True, constrained_layout=True)
    for ax, v, s, name in (
        (axes[0], in_track_km, sigma_in_km, "in-track"),
        (axes[1], cross_track_km, sigma_cross_km, "cross-track"),
    ):
        ax.axhspan(-spec_km, spec_km, color="tab:green", alpha=0.08, label=f"+-{spec_km:g} km specification")
        for y in (-spec_km, spec_km):
            ax.axhline(y, color="tab:green", lw=1, ls="--")
        ax.axhline(0, color="0.6", lw=0.8)
        ok = np.asarray(reliable, bool)
        ax.errorbar(
            FORS[ok],
            np.asarray(v)[ok],
            yerr=np.asarray(s)[ok],
            fmt="o",
            ms=4,
            color="tab:blue",
            capsize=2,
            label="offset +- 1 sigma",
        )
        if np.any(~ok):
            ax.plot(FORS[~ok], np.asarray(v)[~ok], "x", color="tab:red", label="flagged")
        ax.set_title(f"{name} error (km)")
        ax.set_xlabel("FOR (scan position)")
        ax.set_xlim(0, 31)
        ax.grid(alpha=0.3)
    hi = np.nanmax(np.abs(np.concatenate([in_track_km, cross_track_km, [spec_km]])))
    axes[0].set_ylim(-1.15 * hi, 1.15 * hi)
    axes[0].legend(loc="lower left", fontsize=8)
    fig.suptitle(title, fontsize=10)
    return _save(fig, Path(path))


def latest_urad(
    path: PathLike,
    d_alpha_urad: np.ndarray,
    d_beta_urad: np.ndarray,
    sigma_alpha_urad: np.ndarray,
    sigma_beta_urad: np.ndarray,
    title: str,
) -> Path:
    """Per-FOR LOS offset angles in urad with a % of FOV axis (Wang et al. 2017 figure 7).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    d_alpha_urad, d_beta_urad : numpy.ndarray
        Per FOR, urad.
    sigma_alpha_urad, sigma_beta_urad : numpy.ndarray
        Their sigmas, urad.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.4), constrained_layout=True)
    for ax, v, s, name in (
        (axes[0], d_alpha_urad, sigma_alpha_urad, "in-track d_alpha"),
        (axes[1], d_beta_urad, sigma_beta_urad, "cross-track d_beta"),
    ):
        ax.axhline(0, color="0.6", lw=0.8)
        ax.errorbar(FORS, v, yerr=s, fmt="o", ms=4, color="tab:blue", capsize=2)
        ax.set_title(f"{name} (urad)")
        ax.set_xlabel("FOR (scan position)")
        ax.set_xlim(0, 31)
        ax.grid(alpha=0.3)
        pct = ax.secondary_yaxis(
            "right", functions=(lambda u: 100 * u / FOV_DIAMETER_URAD, lambda p: p * FOV_DIAMETER_URAD / 100)
        )
        pct.set_ylabel("% of FOV")
    fig.suptitle(title, fontsize=10)
    return _save(fig, Path(path))


def _days_axis(ax: Axes, days: Sequence[dt.date]) -> None:
    """Limit the date axis to the days shown, each its whole day (drawn centred on its 00:00): the axis
    spans the data and no more (matplotlib would widen a lone day to years, a change far back to decades)."""
    ax.set_xlim(
        mdates.date2num(days[0] - dt.timedelta(hours=12)), mdates.date2num(days[-1] + dt.timedelta(hours=12))
    )
    locator = mdates.AutoDateLocator(minticks=3, maxticks=8, interval_multiples=True)
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))


def _mark_changes(ax: Axes, changes: Marks, label: bool = True) -> None:
    seen = set()
    for when, instrument, _description in changes:
        colour = CHANGE_COLOURS.get(instrument, "0.3")
        lab = f"{instrument} change" if label and instrument not in seen else None
        seen.add(instrument)
        ax.axvline(mdates.date2num(when), color=colour, lw=1.2, ls=":", label=lab)


def heatmaps(
    path: PathLike,
    days: Sequence[dt.date],
    in_track_km: np.ndarray,
    cross_track_km: np.ndarray,
    spec_km: float,
    changes: Marks,
    title: str,
) -> Path:
    """FOR x day heat maps of in-track and cross-track km; *days* (n,) dates, arrays (n, 30), NaN gaps.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    days : sequence of datetime.date
        The days, shape (n,).
    in_track_km, cross_track_km : numpy.ndarray
        Shape (n, 30), km, NaN gaps.
    spec_km : float
        The specification, km: the colour scale's reference.
    changes : Marks
        Known changes, drawn as lines.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    days = [dt.datetime(d.year, d.month, d.day) for d in days]
    x0, x1 = (
        mdates.date2num(days[0] - dt.timedelta(hours=12)),
        mdates.date2num(days[-1] + dt.timedelta(hours=12)),
    )
    vmax = max(
        spec_km,
        float(np.nanmax(np.abs(np.concatenate([in_track_km.ravel(), cross_track_km.ravel()]))))
        if np.any(np.isfinite(in_track_km))
        else spec_km,
    )
    fig, axes = plt.subplots(2, 1, figsize=(11, 5.6), sharex=True, constrained_layout=True)
    for ax, v, name in ((axes[0], in_track_km, "in-track"), (axes[1], cross_track_km, "cross-track")):
        im = ax.imshow(
            np.asarray(v, float).T,
            aspect="auto",
            origin="lower",
            cmap="RdBu_r",
            vmin=-vmax,
            vmax=vmax,
            extent=(x0, x1, 0.5, 30.5),
            interpolation="nearest",
        )
        ax.set_ylabel("FOR")
        ax.set_title(f"{name} error (km)", fontsize=10)
        fig.colorbar(im, ax=ax, label="km", pad=0.01)
        _mark_changes(ax, changes, label=False)
    axes[1].xaxis_date()
    _days_axis(axes[1], days)
    fig.suptitle(title, fontsize=10)
    return _save(fig, Path(path))


def trend_lines(
    path: PathLike,
    days: Sequence[dt.date],
    fors: Sequence[int],
    in_track_km: np.ndarray,
    cross_track_km: np.ndarray,
    spec_km: float,
    changes: Marks,
    alerts: Sequence[dt.datetime],
    title: str,
) -> Path:
    """Chosen FORs over time with the spec band; change lines and alert markers (triangles).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    days : sequence of datetime.date
        The days, shape (n,).
    fors : sequence of int
        The FORs drawn, 1-based.
    in_track_km, cross_track_km : numpy.ndarray
        Shape (n, 30), km.
    spec_km : float
        The specification, km.
    changes : Marks
        Known changes, drawn as lines.
    alerts : sequence of datetime.datetime
        When alerts fired (triangles).
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    days = [dt.datetime(d.year, d.month, d.day) for d in days]
    fig, axes = plt.subplots(2, 1, figsize=(11, 5.6), sharex=True, constrained_layout=True)
    for ax, v, name in ((axes[0], in_track_km, "in-track"), (axes[1], cross_track_km, "cross-track")):
        ax.axhspan(-spec_km, spec_km, color="tab:green", alpha=0.08)
        for y in (-spec_km, spec_km):
            ax.axhline(y, color="tab:green", lw=1, ls="--")
        for k in fors:
            ax.plot(days, v[:, k - 1], "-", marker="." if len(days) < 60 else None, lw=1.2, label=f"FOR {k}")
        _mark_changes(ax, changes, label=ax is axes[0])
        for when in alerts:
            ax.plot(
                [when],
                [spec_km * 1.1],
                "v",
                color="tab:red",
                ms=8,
                label="alert" if ax is axes[0] and when == alerts[0] else None,
            )
        ax.set_ylabel("km")
        ax.set_title(f"{name} error (km)", fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper left", fontsize=8, ncol=4)
    _days_axis(axes[1], days)
    fig.suptitle(title, fontsize=10)
    return _save(fig, Path(path))


def cost_contour(
    path: PathLike,
    cube_k: np.ndarray,
    for_index: int,
    step_urad: float,
    d_alpha_urad: float,
    d_beta_urad: float,
    cost: Cost,
    title: str,
) -> Path:
    """Cost surface G of one FOR over the 21 x 21 offsets with its minimum marked (figure 5c), its colour
    bar naming the cost.

    *cube_k* (2n+1, 2n+1): index i in-track, j cross-track; axes in urad.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    cube_k : numpy.ndarray
        The cost, K, shape (2n+1, 2n+1).
    for_index : int
        The FOR, 1-based.
    step_urad : float
        The grid's step, urad.
    d_alpha_urad, d_beta_urad : float
        The minimum, urad.
    cost : Cost
        The cost the assessment minimised (``assessment.cost``).
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    n = (cube_k.shape[0] - 1) // 2
    offsets = np.arange(-n, n + 1) * step_urad
    fig, ax = plt.subplots(figsize=(5.6, 4.8), constrained_layout=True)
    cs = ax.contourf(offsets, offsets, cube_k, levels=20, cmap="viridis")
    ax.contour(offsets, offsets, cube_k, levels=10, colors="white", linewidths=0.5, alpha=0.6)
    fig.colorbar(cs, ax=ax, label=COST_LABEL[cost])
    i, j = np.unravel_index(np.nanargmin(cube_k), cube_k.shape)
    ax.plot(offsets[j], offsets[i], "r+", ms=16, mew=2, label="grid minimum")
    if np.isfinite(d_alpha_urad) and np.isfinite(d_beta_urad):
        ax.plot(d_beta_urad, d_alpha_urad, "wo", mfc="none", ms=10, label="refined estimate")
    ax.plot(0, 0, "k.", label="as geolocated")
    ax.set_xlabel("cross-track offset d_beta (urad)")
    ax.set_ylabel("in-track offset d_alpha (urad)")
    ax.set_title(f"FOR {for_index}", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    fig.suptitle(title, fontsize=9)
    return _save(fig, Path(path))


def calibration_bins(
    path: PathLike,
    low_k: ArrayLike,
    n: ArrayLike,
    mean_k: ArrayLike,
    std_k: ArrayLike,
    width_k: float,
    title: str,
) -> Path:
    """CrIS minus VIIRS I5 BT against the CrIS BT in bins *width_k* wide at the optimum, with the bins'
    standard deviation and sample count (Wang et al. 2017 figure 15).

    Parameters
    ----------
    path : path-like
        The PNG to write.
    low_k : array_like
        Each bin's lower edge, K.
    n : array_like
        Samples per bin.
    mean_k, std_k : array_like
        CrIS minus VIIRS per bin and its standard deviation, K.
    width_k : float
        The bins' width, K.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    low_k, n, mean_k, std_k = (np.asarray(a, float) for a in (low_k, n, mean_k, std_k))
    centre = low_k + width_k / 2
    fig, ax = plt.subplots(figsize=(7.5, 3.8), constrained_layout=True)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.errorbar(centre, mean_k, yerr=np.nan_to_num(std_k), fmt="o-", capsize=3, color="tab:blue")
    for x, y, k in zip(centre, mean_k, n, strict=True):
        ax.annotate(f"{int(k)}", (x, y), textcoords="offset points", xytext=(0, 8), ha="center", fontsize=7)
    ax.set_xlabel(f"CrIS BT (K), {width_k:g} K bins")
    ax.set_ylabel("CrIS - VIIRS BT (K)")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    return _save(fig, Path(path))


def calibration_trend(
    path: PathLike,
    days: Sequence[dt.date],
    bias_k: np.ndarray,
    gain_pct: np.ndarray,
    changes: Marks,
    title: str,
) -> Path:
    """The daily CrIS-VIIRS bias at the reference temperature and the gain difference (median over the
    reliable FORs, the band between their quartiles), with the known changes.

    Parameters
    ----------
    path : path-like
        The PNG to write.
    days : sequence of datetime.date
        The days, shape (n,).
    bias_k : numpy.ndarray
        Per day and FOR, K.
    gain_pct : numpy.ndarray
        Per day and FOR, per cent.
    changes : Marks
        Known changes, drawn as lines.
    title : str
        The figure's title.

    Returns
    -------
    Path
        The file.
    """
    days = [dt.datetime(d.year, d.month, d.day) for d in days]
    fig, axes = plt.subplots(2, 1, figsize=(11, 5.0), sharex=True, constrained_layout=True)
    for ax, v, label in ((axes[0], bias_k, "bias at 280 K (K)"), (axes[1], gain_pct, "gain (%)")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # days without a fitted FOR: NaN
            q1, med, q3 = np.nanpercentile(v, [25, 50, 75], axis=1)
        ax.fill_between(days, q1, q3, color="tab:blue", alpha=0.2, lw=0)
        ax.plot(days, med, "-", marker="." if len(days) < 60 else None, color="tab:blue", lw=1.2)
        _mark_changes(ax, changes, label=ax is axes[0])
        ax.set_ylabel(label)
        ax.set_title(f"CrIS - VIIRS {label}", fontsize=10)
        ax.grid(alpha=0.3)
    if changes:
        axes[0].legend(loc="upper left", fontsize=8)
    _days_axis(axes[1], days)
    fig.suptitle(title, fontsize=10)
    return _save(fig, Path(path))
