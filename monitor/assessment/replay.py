"""The estimator on the reference implementation's collocations: real radiances in, the same result out.

The public reference implementation of Wang et al. 2017 (``wanglikun1973/CrIS_GEOLOCATION``) writes one
NumPy ``.npz`` per CrIS granule: the CrIS BT in the I5 band and the VIIRS I5 BT of the plain mean radiance
of the pixels in each turned 0.963 deg cone. The SDR team has years of them. Their layout, as data
(:data:`LAYOUT`): axes (beta, alpha, scan, FOR, FOV) for the cone means, (scan, FOR, FOV) for the CrIS BT
and the GEO fields, the turns in radians.

They hold no geometry to turn angles into ground distance (no spacecraft position or attitude), so the km
fields of the result stay empty (NaN) and the result says so in its notes. The estimator
(:mod:`monitor.estimation.estimate`) takes a square grid centred on zero turn: of a rectangular grid (17 alpha
x 15 beta in the files at hand) the centred square of the shorter side is used (15 x 15), and the result says
that too. The cone means are plain means over the top-hat cone, so no footprint is fitted here.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR, N_FOV, URAD
from monitor.core.errors import DataError
from monitor.core.result import FLAG_TOP_HAT, AssessmentResult, GranuleInfo
from monitor.core.vocabulary import Kernel
from monitor.estimation.estimate import ForSamples
from monitor.estimation.jackknife import follows_in_time, uncertainty_note
from monitor.estimation.offsets import day_offsets
from monitor.sdr.names import parse_name

# key: (axes, what it is); axes name the dimensions in the file's order
LAYOUT = {
    "alpha": (("alpha",), "in-track turns of the LOS, rad"),
    "beta": (("beta",), "cross-track turns of the LOS, rad"),
    "cris_v_bt": (("beta", "alpha", "scan", "for", "fov"), "VIIRS I5 BT of the cone mean, K"),
    "cris_c_bt": (("scan", "for", "fov"), "CrIS BT in the I5 band, K"),
    "cris_sdrQa": (("scan", "for", "fov", "flag"), "SCRIF QF3"),
}
BT_RANGE_K = (150.0, 350.0)  # a BT outside this is not a brightness temperature of the Earth
STEP_TOLERANCE = 1e-3  # relative: the turns must be one uniform step, the same in both directions


class ReplayError(DataError):
    """A collocation file that does not hold what the layout says: FILE: FIELD: REASON.

    Parameters
    ----------
    path : Path
        The file.
    field : str
        The array or attribute.
    reason : str
        What is wrong with it.
    """

    def __init__(self, path: Path, field: str, reason: str):
        super().__init__(f"{path}: {field}: {reason}")


@dataclass(frozen=True)
class Collocation:
    """One granule's collocation, on the square grid: *v_bt_k* (scan, FOR, FOV, m, m) with axes (alpha,
    beta) last, *c_bt_k* (scan, FOR, FOV), *usable* (scan, FOR, FOV), the step (rad), and the grid the
    file held (*file_grid*: alpha x beta turns)."""

    path: Path
    v_bt_k: np.ndarray
    c_bt_k: np.ndarray
    usable: np.ndarray
    step_rad: float
    file_grid: tuple[int, int]

    @property
    def half_steps(self) -> int:
        """The grid's perturbations on each side of zero.

        Returns
        -------
        int
            n of the (2n+1) x (2n+1) square.
        """
        return (self.v_bt_k.shape[-1] - 1) // 2


def _array(path: Path, z: Any, key: str) -> np.ndarray:
    axes, _ = LAYOUT[key]
    if key not in z.files:
        raise ReplayError(path, key, "missing")
    a = z[key]
    if a.ndim != len(axes):
        raise ReplayError(path, key, f"has {a.ndim} dimensions, expected {len(axes)} {axes}")
    return a


def _turns(path: Path, key: str, a: np.ndarray) -> float:
    """The uniform step (rad) of the turns *a*, centred on zero."""
    a = np.asarray(a, float)
    if len(a) < 3 or len(a) % 2 == 0 or not np.all(np.isfinite(a)):
        raise ReplayError(path, key, f"{len(a)} turns: expected an odd number of at least 3, finite")
    steps = np.diff(a)
    step = float(np.median(steps))
    if step <= 0 or np.max(np.abs(steps - step)) > STEP_TOLERANCE * step:
        raise ReplayError(
            path, key, f"turns are not one uniform increasing step ({steps.min():.4g}..{steps.max():.4g})"
        )
    if abs(a[len(a) // 2]) > STEP_TOLERANCE * step:
        raise ReplayError(path, key, f"the middle turn is {a[len(a) // 2]:.4g} rad, not zero")
    return step


def read_collocation(path: str | Path) -> Collocation:
    """One reference-implementation ``.npz``, checked against :data:`LAYOUT`.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    Collocation
        Its square grid; a :class:`ReplayError` names the file, the field and what is wrong.
    """
    path = Path(path)
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise ReplayError(path, "(file)", f"not a NumPy .npz archive ({exc})") from None
    with z:
        alpha, beta = _array(path, z, "alpha"), _array(path, z, "beta")
        v, c, qa = _array(path, z, "cris_v_bt"), _array(path, z, "cris_c_bt"), _array(path, z, "cris_sdrQa")
    sa, sb = _turns(path, "alpha", alpha), _turns(path, "beta", beta)
    if abs(sa - sb) > STEP_TOLERANCE * sa:
        raise ReplayError(path, "beta", f"step {sb:.6g} rad differs from alpha's {sa:.6g}")
    if v.shape[:2] != (len(beta), len(alpha)) or v.shape[3:] != (N_FOR, N_FOV):
        raise ReplayError(
            path,
            "cris_v_bt",
            f"shape {v.shape}, expected ({len(beta)}, {len(alpha)}, scans, {N_FOR}, {N_FOV})",
        )
    if c.shape != v.shape[2:]:
        raise ReplayError(path, "cris_c_bt", f"shape {c.shape}, expected {v.shape[2:]}")
    if qa.shape[:3] != c.shape:
        raise ReplayError(path, "cris_sdrQa", f"shape {qa.shape[:3]}, expected {c.shape} (x flags)")
    for key, a in (("cris_c_bt", c), ("cris_v_bt", v)):
        bad = np.isfinite(a) & ((a < BT_RANGE_K[0]) | (a > BT_RANGE_K[1]))
        if bad.any():
            raise ReplayError(
                path, key, f"{int(bad.sum())} value(s) outside {BT_RANGE_K[0]:g}..{BT_RANGE_K[1]:g} K "
                f"(e.g. {a[bad].flat[0]:g})"
            )  # fmt: skip
    n = min(len(alpha), len(beta)) // 2
    ia = slice(len(alpha) // 2 - n, len(alpha) // 2 + n + 1)
    ib = slice(len(beta) // 2 - n, len(beta) // 2 + n + 1)
    v_sq = np.transpose(v[ib, ia], (2, 3, 4, 1, 0)).astype(np.float64)  # (scan, FOR, FOV, alpha, beta)
    usable = np.isfinite(c) & np.all(np.isfinite(v_sq), axis=(-2, -1)) & np.all(qa == 0, axis=-1)
    return Collocation(path, v_sq, np.asarray(c, float), usable, sa, (len(alpha), len(beta)))


def for_samples(granules: list[Collocation], k: int) -> ForSamples:
    """The estimator's input for one FOR over the granules: every usable FOV (cone means only).

    Parameters
    ----------
    granules : list of Collocation
        The collocation files read.
    k : int
        The FOR, 0-based.

    Returns
    -------
    ForSamples
        The FOR's samples.
    """
    d, cris, granule, scan, fov = [], [], [], [], []
    for g_i, g in enumerate(granules):
        use = g.usable[:, k]
        d.append(g.v_bt_k[:, k][use] - g.c_bt_k[:, k][use][:, None, None])
        cris.append(g.c_bt_k[:, k][use])
        scans, fovs = np.nonzero(use)
        granule.append(np.full(scans.size, g_i))
        scan.append(scans)
        fov.append(fovs)
    return ForSamples(
        np.concatenate(d), np.concatenate(cris), np.concatenate(granule), np.concatenate(scan),
        fov=np.concatenate(fov),
    )  # fmt: skip


def granule_info(g: Collocation) -> GranuleInfo:
    """What the result records of one collocation file.

    Parameters
    ----------
    g : Collocation
        The file read.

    Returns
    -------
    GranuleInfo
        Its times (UTC, ISO 8601) from the granule's name, empty for another name.
    """
    n = g.usable.size
    name = parse_name(g.path.name.removesuffix(".npz"))
    return GranuleInfo(
        granule_id=g.path.name,
        start=name.start.isoformat() if name else "",
        end=name.end.isoformat() if name else "",
        cris_geo="",
        cris_sdr=g.path.name,
        viirs=[],
        n_fovs=int(n),
        n_usable=int(g.usable.sum()),
    )


def notes(granules: list[Collocation]) -> list[str]:
    """What the result says of how collocation files were read.

    Parameters
    ----------
    granules : list of Collocation
        The files read.

    Returns
    -------
    list of str
        The result's notes.
    """
    grids = sorted({g.file_grid for g in granules})
    m = granules[0].v_bt_k.shape[-1]
    return [
        "source: the reference implementation's collocation files (cone means over the 0.963 deg top hat)",
        "km fields empty: the files hold no spacecraft position or attitude to turn angles into ground "
        "distance",
        "grid: the centred "
        f"{m} x {m} square of the files' "
        + ", ".join(f"{a} alpha x {b} beta" for a, b in grids)
        + f" turns, step {granules[0].step_rad / URAD:.1f} urad from the files",
        "no footprint fitted: the files hold cone means only; the minimum is the top-hat cone's, which a "
        "smooth CrIS response moves (simulated: 9-16 urad RMS), and its sigmas carry the cone's floor "
        "(flag top_hat)",
        "no parallax correction: cone means cannot be collocated again with the VIIRS pixels at their "
        "clouds' height, so the FOV rows (fov_rows_*) show the raw parallax of the day's clouds as well as "
        "any error of the EP's FOV positions (parallax_* fields empty)",
    ]


def _start_s(path: Path) -> float:
    """The start (s since the epoch) in a collocation file's name, the granule's SCRIF name with ``.npz``
    appended; NaN for another name (then it follows no other granule)."""
    name = parse_name(path.name.removesuffix(".npz"))
    return name.start.replace(tzinfo=dt.timezone.utc).timestamp() if name else np.nan


def assess_collocations(
    paths: Iterable[str | Path], cfg: AssessmentConfig, satellite: str = ""
) -> AssessmentResult:
    """The estimator's result for the reference implementation's collocation files.

    Parameters
    ----------
    paths : iterable of str or Path
        The files, one granule each, all on one grid.
    cfg : AssessmentConfig, optional
        The assessment's configuration (the cost).
    satellite : str, optional
        The satellite's short name.

    Returns
    -------
    AssessmentResult
        Per-FOR offsets in urad with jackknife sigmas, flags (``top_hat``: cone means) and the
        intercalibration; the km fields NaN (the files hold no geometry).
    """
    granules = sorted((read_collocation(p) for p in paths), key=lambda g: (_start_s(g.path), g.path.name))
    if not granules:
        raise DataError("no collocation files given")
    first = granules[0]
    for g in granules[1:]:
        if (
            g.v_bt_k.shape[-1] != first.v_bt_k.shape[-1]
            or abs(g.step_rad - first.step_rad) > STEP_TOLERANCE * first.step_rad
        ):
            raise ReplayError(g.path, "alpha", f"grid differs from {first.path.name}'s")
    cones = cfg.model_copy(update={"kernel": Kernel.TOP_HAT})
    day = day_offsets(
        [for_samples(granules, k) for k in range(N_FOR)],
        cones,
        first.step_rad / URAD,
        follows=follows_in_time([_start_s(g.path) for g in granules]),
    )
    fors = day.fors
    if cfg.kernel != Kernel.TOP_HAT:  # the cone's estimate where the footprint is configured: said per FOR
        fors = [replace(f, flags=tuple(sorted({*f.flags, FLAG_TOP_HAT}))) for f in fors]
    infos = [granule_info(g) for g in granules]
    return AssessmentResult(
        satellite=satellite,
        start=min((i.start for i in infos if i.start), default=""),
        end=max((i.end for i in infos if i.end), default=""),
        fors=fors,
        granules=infos,
        half_steps=first.half_steps,
        step_urad=first.step_rad / URAD,
        cost_cube_k=day.cost_cube_k,
        difference_bins=day.difference_bins,
        notes=[*notes(granules), uncertainty_note(len(granules), day.correlation)],
    )
