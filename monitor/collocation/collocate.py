"""CrIS-VIIRS collocation by the line-of-sight angle test (Wang et al. 2016), for all perturbed LOS at once.

A VIIRS pixel at ECEF point P belongs to a CrIS FOV seen from S along L when the angle between
unit(P - S) and L is within the FOV half-angle h. For the (2n+1)^2 perturbed LOS of section 2.3,

    L_ij = unit(tan A_i, tan B_j, 1),  A_i = alpha + (i - n) s,  B_j = beta + (j - n) s   (SBF),

the test d . L_ij >= cos h for a pixel direction d is, for fixed i, a quadratic inequality in
t = tan B_j whose solution is one interval. So each pixel adds its value to one run of j per row i,
and the 441 cone sums are prefix sums of these runs: exact, and 21 operations per pixel instead of 441.

The pixels (3-D points, band radiance, solid-angle weights, search blocks) come prepared by
:mod:`monitor.collocation.swath`; the cone sums of a FOV add over pixels, so each prepared granule is searched
on its own.

Search. Each prepared granule keeps, per 4 x 4 block of pixels (blocks never straddle two scans), a
sphere holding its usable pixels. Around each FOV only the blocks whose sphere comes within the union
of the perturbed cones are opened. A row/column window alone would take in whole stretches of the
neighbouring scans (bow-tie overlap) that lie outside the cones; testing a block costs a sixteenth of
testing its pixels.

Compiled. The search, the interval test and the accumulation run in one numba kernel, in parallel over
FOVs; each FOV accumulates its own (2n+1) x (2n+2) difference array, so threads never share a sum. Its
entries are complex, weight x radiance + i weight: the two sums a pixel adds to are one 16-byte
read-modify-write at each end of its run, not two.
The j run of an interval [t_lo, t_hi] is found by comparing with the FOV's tan B_j (no arctangent), for
all rows in one loop of selects, not branches (the accumulation, a scatter, is a loop of its own). The
kernel uses numba's numpy error model (a division by zero gives inf or NaN, which it tests for).
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numba
import numpy as np

from monitor.collocation import render
from monitor.collocation.sums import ConeSums, cone_sums_of, smoothed
from monitor.collocation.swath import BLOCK_PX, SwathPiece, ViirsSwath, swath_piece
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import FOV_HALF_ANGLE_RAD, MAX_GRID_SPREAD_RAD, VIIRS_DETECTORS
from monitor.geometry import wgs84
from monitor.instrument.spectral import PARALLEL_FROM, i5_band

# The discs (radii, rad) whose sums the kernel returns. The top-hat cone of the paper is one disc; the
# annuli between nested discs let the estimator fit the CrIS spatial response (monitor.estimation.estimate):
# CrIS sees a smooth, radially symmetric response, 70 % of peak at 0.437 deg from the LOS and 3 % at 0.619 deg
# at most (Wang slides, table 3, monitor.instrument.footprint), so the annuli reach past the cone to 0.64 deg.
# Four discs: the kernel's work grows with their number, and three (no edge inside the cone) would miss
# the response's fall from 0.42 to 0.48 deg (studies/footprint.md).
TOP_HAT = (FOV_HALF_ANGLE_RAD,)
ANNULI = (math.radians(0.42), FOV_HALF_ANGLE_RAD, math.radians(0.56), math.radians(0.64))
# The kernel's threads take FOVs in chunks of this many as they come free (FOVs differ in pixel count, and
# the read-ahead thread takes turns on the cores), not in equal shares fixed in advance
FOVS_PER_TASK = 8
# VIIRS columns are prepared out to the farthest view angle a cone reaches plus this: the two instruments
# see a ground point from spacecraft positions seconds apart (its cross-track angle differs by far less)
VIEW_MARGIN_RAD = math.radians(0.5)
# VIIRS scans are prepared from this long before a CrIS granule's first observation to this long after its
# last: the instruments see a ground point within seconds of each other (a corner FOV lies ~1.1 deg, a cone
# reaches ~0.9 deg, from the FOR's LOS: ~55 km or 9 s of flight along the track at the swath edge)
SCAN_TIME_MARGIN_US = 16_000_000


def reach_rad(offsets_rad: np.ndarray, radii_rad: tuple[float, ...] = TOP_HAT) -> float:
    """The angle from a FOV's LOS within which one of its perturbed discs can hold a pixel.

    Parameters
    ----------
    offsets_rad : numpy.ndarray
        The perturbation grid (2n+1,), rad.
    radii_rad : tuple of float
        The discs' half-angles, rad, increasing.

    Returns
    -------
    float
        The angle, rad.
    """
    return max(radii_rad) + float(np.abs(offsets_rad).max()) * math.sqrt(2.0) * 1.02


def box_half_widths_rad(
    beta_rad: np.ndarray | float, offsets_rad: np.ndarray, radii_rad: tuple[float, ...] = TOP_HAT
) -> tuple[np.ndarray | float, float]:
    """The half-widths in alpha and beta of the box about a FOV's LOS that holds all its perturbed discs.

    The grid's reach plus the largest disc, 2 % wider; in alpha over cos beta, the SBF alpha of a fixed angle
    growing with the cross-track angle.

    Parameters
    ----------
    beta_rad : numpy.ndarray or float
        The FOV's cross-track angle, rad.
    offsets_rad : numpy.ndarray
        The perturbation grid (2n+1,), rad.
    radii_rad : tuple of float
        The discs' half-angles, rad, increasing.

    Returns
    -------
    alpha_half_rad, beta_half_rad : numpy.ndarray or float
        The half-widths, rad.
    """
    big, h_max = float(np.abs(offsets_rad).max()), max(radii_rad)
    return big + 1.02 * h_max / np.cos(beta_rad), big + 1.02 * h_max


def los_ecef(sbf_to_ecef: np.ndarray, alpha_rad: np.ndarray, beta_rad: np.ndarray) -> np.ndarray:
    """The unit LOS in ECEF of FOVs at spacecraft-body-frame angles (equations 1-2).

    Parameters
    ----------
    sbf_to_ecef : numpy.ndarray
        Each FOV's rotation from the spacecraft body frame to ECEF, shape (F, 3, 3).
    alpha_rad, beta_rad : numpy.ndarray
        Each FOV's in-track and cross-track LOS angles in the spacecraft body frame, rad, shape (F,).

    Returns
    -------
    numpy.ndarray
        Unit vectors, ECEF, shape (F, 3).
    """
    t = np.stack([np.tan(alpha_rad), np.tan(beta_rad), np.ones(np.shape(alpha_rad))], -1)
    los = np.einsum("fij,fj->fi", sbf_to_ecef, t)
    return los / np.linalg.norm(los, axis=-1, keepdims=True)


def view_reach_rad(
    sat_m: np.ndarray,
    sbf_to_ecef: np.ndarray,
    alpha_rad: np.ndarray,
    beta_rad: np.ndarray,
    offsets_rad: np.ndarray,
    radii_rad: tuple[float, ...] = TOP_HAT,
) -> float:
    """The farthest angle from the geocentric nadir that a perturbed cone of these FOVs reaches, plus a
    margin.

    The VIIRS columns beyond it need no preparation (:func:`reach.view_columns`).

    Parameters
    ----------
    sat_m : numpy.ndarray
        Each FOV's satellite position, ECEF, m, shape (F, 3).
    sbf_to_ecef : numpy.ndarray
        Each FOV's rotation from the spacecraft body frame to ECEF, shape (F, 3, 3).
    alpha_rad, beta_rad : numpy.ndarray
        Each FOV's in-track and cross-track LOS angles in the spacecraft body frame, rad, shape (F,).
    offsets_rad : numpy.ndarray
        The perturbation grid (2n+1,), rad.
    radii_rad : tuple of float
        The discs' half-angles, rad, increasing.

    Returns
    -------
    float
        The angle plus :data:`VIEW_MARGIN_RAD`, rad; pi when there is no FOV (NaN FOVs are ignored).
    """
    los = los_ecef(sbf_to_ecef, alpha_rad, beta_rad)
    nadir = -np.asarray(sat_m, float) / np.linalg.norm(sat_m, axis=-1, keepdims=True)
    off = np.arccos(np.clip(np.sum(los * nadir, -1), -1.0, 1.0))
    if not np.isfinite(off).any():
        return math.pi
    return float(np.nanmax(off)) + reach_rad(offsets_rad, radii_rad) + VIEW_MARGIN_RAD


def _window_half_sizes(
    piece: SwathPiece, col0: np.ndarray, range_m: np.ndarray, cos_zen: np.ndarray, reach_angle_rad: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row and column half-widths (pixels) of the search window around each FOV centre pixel.

    The centre is the pixel nearest the LOS's ellipsoid point; pixels on terrain of height h meet the
    LOS up to h tan(zenith) before it, so both widths grow by that relief displacement.
    """
    cz = np.maximum(cos_zen, 0.2)
    relief = piece.max_height_m * np.sqrt(1.0 - cz * cz) / cz
    d_track = reach_angle_rad * range_m + relief
    d_scan = reach_angle_rad * range_m / cz + relief
    adv = piece.advance_m[col0]
    det = piece.det_step_m[col0]
    n = piece.detectors
    overlap = np.clip(1.0 - adv / (n * det), 0.0, 1.0)
    half_rows = np.ceil(d_track / (adv / n) + n * overlap + 8).astype(np.int64)
    half_cols = np.ceil(d_scan / piece.col_spacing_m[col0] + 4).astype(np.int64)
    return half_rows, half_cols, np.maximum(d_track, d_scan)


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _nearest_index(t: float, guess0: float, guess_scale: float, m: int) -> int:
    """The j nearest t on the chord through (tan B_0, 0) and (tan B_{m-1}, m - 1), clipped to 0..m
    (0 for NaN)."""
    g = (t - guess0) * guess_scale + 0.5
    g = g if g > 0.0 else 0.0
    return int(g if g < m else m)


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _run_ends(
    tan_b_inf: np.ndarray,
    t_lo: np.ndarray,
    t_hi: np.ndarray,
    guess0: float,
    guess_scale: float,
    j_first: np.ndarray,
    j_after: np.ndarray,
) -> None:
    """The run of j with t_lo <= tan B_j <= t_hi in each row: its first j and the j after its last
    (j_first >= j_after: empty, as for a NaN interval). *tan_b_inf* is tan B_0 .. tan B_{m-1}, +inf.

    tan B_j departs from the chord of :func:`_nearest_index` by at most tan|beta| n^2 s (index units),
    < 0.3 within MAX_GRID_SPREAD_RAD, so the count of tan B_j below t is the nearest index or the next:
    one comparison settles it. Selects, not branches, so that the loop vectorises.
    """
    m = tan_b_inf.shape[0] - 1
    for i in range(t_lo.shape[0]):
        t = t_lo[i]
        j = _nearest_index(t, guess0, guess_scale, m)
        j_first[i] = j + (tan_b_inf[j] < t)
        t = t_hi[i]
        j = _nearest_index(t, guess0, guess_scale, m)
        j_after[i] = min(j + (tan_b_inf[j] <= t), m)


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _accumulate(
    ecef: np.ndarray,
    radiance: np.ndarray,
    area: np.ndarray,
    block_centre: np.ndarray,
    block_radius: np.ndarray,
    sat: np.ndarray,
    mat: np.ndarray,
    los0: np.ndarray,
    reach0: float,
    tan_a: np.ndarray,
    tan_b: np.ndarray,
    box: np.ndarray,
    block_row: np.ndarray,
    block_col: np.ndarray,
    half_brows: np.ndarray,
    half_bcols: np.ndarray,
    ring_g2: np.ndarray,
    cos_whole: np.ndarray,
    order: np.ndarray,
    rendered: np.ndarray,
    view: np.ndarray,
    view_w: np.ndarray,
    acc: np.ndarray,
    acc_rendered: np.ndarray,
    whole: np.ndarray,
    whole_rendered: np.ndarray,
) -> None:
    """Add the pixels of one prepared granule to each FOV's cone sums (difference arrays along j).

    Per FOV f: satellite *sat* (3), SBF-to-ECEF *mat* (3, 3), unit LOS *los0*; *reach0* the angle (rad) within
    which a pixel can lie in some cone, tan A_i and tan B_j (m), the tangent box (4,) of the cones' union, and
    the search window of blocks (centre block_row/col +- half_brows/bcols; negative: none). *ring_g2* is cos^2
    h of each disc, largest first. FOVs are taken in *order*, in chunks of FOVS_PER_TASK.
    A pixel within the angle whose cosine is *cos_whole* (per disc) of the LOS lies in every cone of that
    disc: its weights go to *whole* (F, discs), every perturbation's share, instead of 2m runs' ends.
    acc (F, discs, m, m + 1) complex receives, per disc, runs of weight x radiance (rows, cols) (real) and
    weight (imaginary): +w at the first j, -w after the last. The discs are nested: where a row's interval of
    a disc is empty, so are those of the smaller discs. When *acc_rendered* has FOVs, it receives the same
    runs of what FOV f sees of the pixel rendered (:mod:`monitor.collocation.render`): (1 - view_w[f])
    times view view[f] of *rendered* (views, rows, cols) plus view_w[f] times the next (and
    *whole_rendered*); the cone test, the costly part, is made once for both.
    """
    ncol = radiance.shape[1]
    with_rendered = acc_rendered.shape[0] > 0
    nbr, nbc = block_radius.shape
    m = tan_a.shape[1]
    nk = ring_g2.shape[0]
    for q in numba.prange(order.shape[0]):
        f = order[q]
        if half_brows[f] < 0:
            continue
        ta = tan_a[f]
        out = acc[f]
        out_rendered = acc_rendered[f if with_rendered else 0]
        all_in = whole[f]
        all_in_rendered = whole_rendered[f if with_rendered else 0]
        seen = rendered[view[f]]
        w_next = view_w[f]
        seen_next = rendered[min(view[f] + 1, rendered.shape[0] - 1)]
        g2k = np.empty((nk, m))  # g2 K = cos^2 h (1 + tan^2 A_i)
        for k in range(nk):
            for i in range(m):
                g2k[k, i] = ring_g2[k] * (1.0 + ta[i] * ta[i])
        tan_b_inf = np.empty(m + 1)  # tan B_0 .. tan B_{m-1}, +inf
        tan_b_inf[:m] = tan_b[f]
        tan_b_inf[m] = np.inf
        guess0 = tan_b[f, 0]
        guess_scale = (m - 1) / (tan_b[f, m - 1] - tan_b[f, 0]) if m > 1 else 0.0
        t_lo = np.empty(m)
        t_hi = np.empty(m)
        b1_row = np.empty(m)
        c2_row = np.empty(m)
        j_first = np.empty(m, np.int64)
        j_after = np.empty(m, np.int64)
        sx, sy, sz = sat[f, 0], sat[f, 1], sat[f, 2]
        m00, m01, m02 = mat[f, 0, 0], mat[f, 0, 1], mat[f, 0, 2]
        m10, m11, m12 = mat[f, 1, 0], mat[f, 1, 1], mat[f, 1, 2]
        m20, m21, m22 = mat[f, 2, 0], mat[f, 2, 1], mat[f, 2, 2]
        lx, ly, lz = los0[f, 0], los0[f, 1], los0[f, 2]
        a_lo, a_hi, b_lo, b_hi = box[f, 0], box[f, 1], box[f, 2], box[f, 3]
        for br in range(max(block_row[f] - half_brows[f], 0), min(block_row[f] + half_brows[f] + 1, nbr)):
            for bc in range(max(block_col[f] - half_bcols[f], 0), min(block_col[f] + half_bcols[f] + 1, nbc)):
                rad = block_radius[br, bc]
                if not rad >= 0.0:  # no usable pixel (NaN)
                    continue
                vx = block_centre[br, bc, 0] - sx
                vy = block_centre[br, bc, 1] - sy
                vz = block_centre[br, bc, 2] - sz
                dist = math.sqrt(vx * vx + vy * vy + vz * vz)
                reach = reach0 + math.asin(min(rad / dist, 1.0))
                if reach < math.pi and vx * lx + vy * ly + vz * lz < dist * math.cos(reach):
                    continue
                for r in range(br * BLOCK_PX, (br + 1) * BLOCK_PX):
                    for c in range(bc * BLOCK_PX, min((bc + 1) * BLOCK_PX, ncol)):
                        value = np.float64(radiance[r, c])
                        if not math.isfinite(value):
                            continue
                        px = np.float64(ecef[r, c, 0]) - sx
                        py = np.float64(ecef[r, c, 1]) - sy
                        pz = np.float64(ecef[r, c, 2]) - sz
                        dx = px * m00 + py * m10 + pz * m20
                        dy = px * m01 + py * m11 + pz * m21
                        dz = px * m02 + py * m12 + pz * m22
                        # The union of the perturbed cones is a rounded rectangle in (alpha, beta): drop
                        # what lies outside, comparing tangents (d_z > 0 within reach of the LOS).
                        if dx < a_lo * dz or dx > a_hi * dz or dy < b_lo * dz or dy > b_hi * dz:
                            continue
                        dist2 = px * px + py * py + pz * pz
                        dist = math.sqrt(dist2)
                        a_dot = area[r, c, 0] * px + area[r, c, 1] * py + area[r, c, 2] * pz
                        weight = abs(a_dot) / (dist2 * dist)  # steradians seen from CrIS
                        dx, dy, dz = dx / dist, dy / dist, dz / dist
                        near = (px * lx + py * ly + pz * lz) / dist  # the cosine of its angle from the LOS
                        wz = complex(weight * value, weight)
                        wr = 0j
                        if with_rendered:
                            view_value = np.float64(seen[r, c])
                            if w_next > 0.0:
                                view_value += w_next * (np.float64(seen_next[r, c]) - view_value)
                            if math.isfinite(view_value):
                                wr = complex(weight * view_value, weight)
                        for i in range(m):  # per row i, what every disc's interval shares
                            ci = ta[i] * dx + dz
                            b1_row[i] = ci * dy
                            c2_row[i] = ci * ci
                        for k in range(nk):
                            if near >= cos_whole[k]:  # within every cone of disc k
                                all_in[k] += wz
                                if with_rendered:
                                    all_in_rendered[k] += wr
                                continue
                            a2 = dy * dy - ring_g2[k]
                            inv_a2 = 1.0 / a2
                            for i in range(m):  # the interval of t = tan B per row i
                                # (c + dy t)^2 >= g2 (K + t^2), c = dx tan A_i + dz: a2 t^2 + 2 b1 t + e >= 0
                                b1 = b1_row[i]
                                disc = b1 * b1 - a2 * (c2_row[i] - g2k[k, i])
                                sq = math.sqrt(max(disc, 0.0))
                                t_lo[i] = (sq - b1) * inv_a2 if disc >= 0.0 else np.inf
                                t_hi[i] = -(b1 + sq) * inv_a2 if disc >= 0.0 else -np.inf
                            _run_ends(tan_b_inf, t_lo, t_hi, guess0, guess_scale, j_first, j_after)
                            inside = False
                            for i in range(m):  # its run of j: +w at the first, -w after the last
                                j0 = j_first[i]
                                j1 = j_after[i]
                                if j0 < j1:
                                    out[k, i, j0] += wz
                                    out[k, i, j1] -= wz
                                    if with_rendered:
                                        out_rendered[k, i, j0] += wr
                                        out_rendered[k, i, j1] -= wr
                                    inside = True
                            if not inside:  # in no cone of this disc: in none of the smaller ones
                                break


def _views(view_alpha_rad: np.ndarray, alpha_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per FOV (in-track SBF angle *alpha_rad*) the view at or below its angle among *view_alpha_rad*
    (increasing) and the linear weight of the next one (0 beyond the ends: the nearest view alone)."""
    angles = np.asarray(view_alpha_rad, np.float64)
    a = np.clip(np.nan_to_num(np.asarray(alpha_rad, np.float64)), angles[0], angles[-1])
    view = np.clip(np.searchsorted(angles, a, side="right") - 1, 0, len(angles) - 1)
    upper = angles[np.minimum(view + 1, len(angles) - 1)]
    with np.errstate(invalid="ignore", divide="ignore"):
        weight = np.where(upper > angles[view], (a - angles[view]) / (upper - angles[view]), 0.0)
    return view.astype(np.int64), weight


def cone_sums(
    swath: ViirsSwath,
    sat_m: np.ndarray,
    sbf_to_ecef: np.ndarray,
    alpha_rad: np.ndarray,
    beta_rad: np.ndarray,
    offsets_rad: np.ndarray,
    radii_rad: tuple[float, ...] = TOP_HAT,
    fov_range_m: np.ndarray | None = None,
    fov_cos_zen: np.ndarray | None = None,
    smooth: bool = False,
) -> ConeSums:
    """Solid-angle weighted VIIRS radiance sums in nested discs about every perturbed LOS of a batch of FOVs.

    A pixel belongs to a disc when the angle between (pixel - satellite) and the LOS is within its half-angle
    (Wang et al. 2016): one quadratic inequality in tan(beta_j) per in-track turn. When the pieces are
    rendered for several in-track angles (clouds with height,
    :attr:`monitor.collocation.swath.SwathPiece.rendered`), the same pass sums what each FOV sees of them into
    :attr:`ConeSums.rendered`: the two views about its own alpha, weighted linearly (the nearest beyond the
    ends).

    Parameters
    ----------
    swath : ViirsSwath
        The prepared VIIRS granules the cones may reach.
    sat_m : numpy.ndarray
        Each FOV's satellite position, ECEF, m, shape (F, 3).
    sbf_to_ecef : numpy.ndarray
        Each FOV's rotation from the spacecraft body frame to ECEF, shape (F, 3, 3).
    alpha_rad, beta_rad : numpy.ndarray
        Each FOV's in-track and cross-track LOS angles in the spacecraft body frame, rad, shape (F,).
    offsets_rad : numpy.ndarray
        The perturbation grid (2n+1,), rad.
    radii_rad : tuple of float
        The discs' half-angles, rad, increasing (:data:`TOP_HAT`: the paper's cone; :data:`ANNULI`).
    fov_range_m : numpy.ndarray, optional
        Each FOV's range to the ground, m, for the search's reach.
    fov_cos_zen : numpy.ndarray, optional
        The cosine of each FOV's zenith angle, for the search's reach.
    smooth : bool, optional
        Smooth the sums over neighbouring perturbations (:func:`monitor.collocation.sums.smoothed`): for a
        grid whose pixels are wider than the perturbation step (``smoothed_cones`` of
        :data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    ConeSums
        The sums, weights and solid angles of every disc, and of the rendered views when the pieces hold them.
    """
    nf = len(alpha_rad)
    m = len(offsets_rad)
    sat_m = np.ascontiguousarray(sat_m, np.float64)
    mat = np.ascontiguousarray(sbf_to_ecef, np.float64)
    if list(radii_rad) != sorted(radii_rad):
        raise ValueError(f"disc radii must increase: {radii_rad}")
    big = np.abs(offsets_rad).max()
    if m > 1 and big * big / (offsets_rad[1] - offsets_rad[0]) > MAX_GRID_SPREAD_RAD * (1 + 1e-9):
        raise ValueError(
            f"perturbation grid of {m} x {m} steps of {offsets_rad[1] - offsets_rad[0]:.3g} rad: n^2 s "
            f"exceeds {MAX_GRID_SPREAD_RAD} rad, beyond the compiled kernel's index guess"
        )
    reach_angle_rad = reach_rad(offsets_rad, radii_rad)  # how far from the LOS a cone reaches
    los0 = los_ecef(mat, alpha_rad, beta_rad)
    t = wgs84.intersect_ellipsoid(sat_m, los0)
    ok_fov = np.isfinite(t)
    centre = sat_m + np.where(ok_fov, t, 0.0)[:, None] * los0
    rng = np.where(ok_fov, fov_range_m if fov_range_m is not None else t, 1e6)
    cz = fov_cos_zen if fov_cos_zen is not None else np.abs(np.sum(wgs84.geodetic_up(centre) * los0, -1))
    cz = np.where(ok_fov, cz, 1.0)
    half_a, half_b = box_half_widths_rad(beta_rad, offsets_rad, radii_rad)
    box = np.tan(np.stack([alpha_rad - half_a, alpha_rad + half_a, beta_rad - half_b, beta_rad + half_b], -1))
    tan_a = np.tan(offsets_rad[None, :] + alpha_rad[:, None])
    tan_b = np.tan(offsets_rad[None, :] + beta_rad[:, None])
    ring_g2 = np.cos(np.asarray(radii_rad[::-1], np.float64)) ** 2  # the kernel takes the largest first
    acc = np.zeros((nf, len(radii_rad), m, m + 1), np.complex128)
    whole = np.zeros((nf, len(radii_rad)), np.complex128)
    # a pixel this close to the LOS lies in every perturbed cone of a disc: the grid's reach (as the
    # search's) from the disc's edge; 2 where the grid reaches farther than the disc
    spread = reach_angle_rad - max(radii_rad)
    edge = np.asarray(radii_rad[::-1], np.float64) - spread
    cos_whole = np.where(edge > 0, np.cos(edge), 2.0)
    rendered_pieces = sum(p.rendered is not None for p in swath.pieces)
    if rendered_pieces not in (0, len(swath.pieces)):
        raise ValueError("the pieces of a swath are all rendered or none")
    acc_rendered = np.zeros((nf if rendered_pieces else 0, *acc.shape[1:]), np.complex128)
    whole_rendered = np.zeros((len(acc_rendered), len(radii_rad)), np.complex128)
    unrendered = np.zeros((1, 1, 1), np.float32), np.zeros(nf, np.int64), np.zeros(nf)  # views, view, weight
    # FOVs interleaved by thread count: each thread's first share is spread over the granule (the scans
    # that a VIIRS granule reaches are a contiguous part of it)
    threads = numba.get_num_threads()
    order = np.concatenate([np.arange(t0, nf, threads) for t0 in range(threads)])
    for piece in swath.pieces:
        rendered, view, view_w = unrendered
        if piece.rendered is not None:
            rendered, (view, view_w) = piece.rendered, _views(piece.view_alpha_rad, alpha_rad)
        row0, col0, dist = piece.nearest(centre)
        hr, hc, reach_m = _window_half_sizes(piece, col0, rng, cz, reach_angle_rad)
        # a FOV whose cones cannot reach this granule's nearest usable block skips it
        far = ~ok_fov | (dist > reach_m + 2 * BLOCK_PX * piece.col_spacing_m[col0] + piece.advance_m[col0])
        with KERNEL_LOCK, numba.parallel_chunksize(FOVS_PER_TASK):
            _accumulate(
                piece.ecef_m, piece.radiance, piece.area_vec_m2, piece.block_centre_m, piece.block_radius_m,
                sat_m, mat, los0, reach_angle_rad * 1.01, tan_a, tan_b, box,
                row0 // BLOCK_PX, col0 // BLOCK_PX,
                np.where(far, -1, hr // BLOCK_PX + 1), hc // BLOCK_PX + 1, ring_g2, cos_whole, order,
                rendered, view, view_w, acc, acc_rendered, whole, whole_rendered,
            )  # fmt: skip
    solid = 2 * np.pi * (1 - np.cos(np.asarray(radii_rad[::-1], np.float64)))
    rendered_sums = None
    if len(acc_rendered):
        rendered_sums = cone_sums_of(acc_rendered, whole_rendered, solid, radii_rad)
    cones = replace(cone_sums_of(acc, whole, solid, radii_rad), rendered=rendered_sums)
    return smoothed(cones) if smooth else cones


def warm_up() -> float:
    """Compile the kernels, or load them from numba's cache, on a tiny synthetic granule: a timing, or the
    first granule, then does not pay for it.

    Returns
    -------
    float
        The seconds it took.
    """
    t0 = time.perf_counter()
    rows, cols = 2 * VIIRS_DETECTORS, 16
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    lat, lon = np.radians(0.004 * r).astype(np.float32), np.radians(0.004 * c).astype(np.float32)
    zeros = np.zeros((rows, cols), np.float32)
    fields = (lat, lon, zeros, zeros + 280.0, zeros == 0)
    kept = [a[:, 2:] for a in fields]  # the kept columns of a granule: strided views
    swath_piece(kept[0], kept[1], kept[2], kept[3], kept[4], i5_band("j01"))
    piece = swath_piece(*fields, i5_band("j01"))
    ground = wgs84.geodetic_to_ecef(np.radians(0.06), np.radians(0.03), 0.0)
    sat = ground * (1 + 833e3 / np.linalg.norm(ground))
    scans = np.tile(sat, (rows // VIIRS_DETECTORS, 1))
    velocity = np.cross(scans, [0.0, 0.0, 1.0])
    render.rendered_bt(lat, lon, zeros, zeros + 280.0, zeros == 0, scans, velocity, np.zeros(3), 150.0)
    z = -ground / np.linalg.norm(ground)
    x = np.cross([0.0, 0.0, 1.0], z)
    sbf = np.stack([x, np.cross(z, x), z], axis=1)
    offsets = np.array([-1e-3, 0.0, 1e-3])
    cones = cone_sums(ViirsSwath([piece]), sat[None], sbf[None], np.zeros(1), np.zeros(1), offsets)
    for radiance in (
        cones.mean(),
        np.full(PARALLEL_FROM, 5.0),
    ):  # the inversion's serial and parallel kernels
        i5_band("j01").bt_from_radiance(radiance)
    return time.perf_counter() - t0
