"""CrIS-VIIRS collocation by the line-of-sight angle test (Wang et al. 2016), for all perturbed LOS at once.

A VIIRS pixel at ECEF point P belongs to a CrIS FOV seen from S along L when the angle between
unit(P - S) and L is within the FOV half-angle h. For the (2n+1)^2 perturbed LOS of section 2.3,

    L_ij = unit(tan A_i, tan B_j, 1),  A_i = alpha + (i - n) s,  B_j = beta + (j - n) s   (SBF),

the test d . L_ij >= cos h for a pixel direction d is, for fixed i, a quadratic inequality in
t = tan B_j whose solution is one interval. So each pixel adds its value to one run of j per row i,
and the 441 cone sums are prefix sums of these runs: exact, and 21 operations per pixel instead of 441.

Pixels where they are. A terrain-corrected (GITCO) pixel is the 3-D point where its line of sight meets
the terrain: (lat, lon, Height). Put at h = 0 instead, a pixel on terrain of height h seen from CrIS at
view zenith z moves by about h sin(z) / range towards nadir (~0.5 mrad for 1 km at the scan edge), so
every position below is the 3-D point; the ellipsoid product (GIMGO) has h = 0.

Weights. CrIS sees the scene averaged over the solid angle of its FOV; VIIRS pixels do not sample
that solid angle evenly (scan overlap towards the swath edge, footprint steps at the aggregation-zone
edges). Each pixel is weighted by the solid angle it covers seen from CrIS,
``w = |A . u| / range^2``, where ``A`` is the pixel's vector footprint (the cross product of the steps to
its neighbours, so that a slope is foreshortened as seen along the unit direction ``u`` from CrIS) with
the overlap between consecutive scans removed (the part of a footprint that a neighbouring scan also
covers counts half). The sum of the weights inside a cone over the cone's solid angle is its coverage:
1 when VIIRS fills it.

Search. Each prepared granule keeps, per 4 x 4 block of pixels (blocks never straddle two scans), a
sphere holding its usable pixels. Around each FOV only the blocks whose sphere comes within the union
of the perturbed cones are opened. A row/column window alone would take in whole stretches of the
neighbouring scans (bow-tie overlap) that lie outside the cones; testing a block costs a sixteenth of
testing its pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from monitor.constants import FOV_DIAMETER_RAD
from monitor.geometry import wgs84

DETECTORS = 32
TOP_HAT = ((FOV_DIAMETER_RAD / 2, 1.0),)
# CrIS spatial response as a staircase of concentric top hats, from the 70/50/10/3 % full widths of
# 0.8735, 0.942, 1.100 and 1.238 deg (Wang slides, table 3): weight 1 inside 0.4368 deg, then 0.6,
# 0.3 and 0.065 out to 0.619 deg.
SPATIAL_RESPONSE = tuple(
    (np.radians(r), c) for r, c in ((0.4368, 0.4), (0.471, 0.3), (0.550, 0.235), (0.619, 0.065))
)
MIN_COVERAGE = 0.97
BLOCK = 4096  # candidate pixels per block of the interval computation
BLOCK_PX = 4  # VIIRS pixels are searched in BLOCK_PX x BLOCK_PX blocks (a divisor of DETECTORS)
PAD = 48  # margin of the j difference arrays, wider than any run beyond the grid (2h/s ~ 37)


@dataclass
class PixelArrays:
    """VIIRS I5 pixels ready for collocation, rows of 32-detector scans.

    ecef_m (rows, cols, 3) float32 (0.5 m resolution) of the 3-D pixel points; radiance (rows, cols) I5 band
    radiance mW/(m2 sr cm-1), NaN where unusable; area_vec_m2 (rows, cols, 3) float32 the vector footprint
    with scan overlap removed. block_centre_m (rows/4, cols/4, 3) and block_radius_m bound the usable pixels
    of each 4 x 4 block (NaN where it has none); per-column spacings (m) and the highest pixel
    (max_height_m) size the search windows.
    """

    ecef_m: np.ndarray
    radiance: np.ndarray
    area_vec_m2: np.ndarray
    block_centre_m: np.ndarray
    block_radius_m: np.ndarray
    col_spacing_m: np.ndarray
    advance_m: np.ndarray
    det_step_m: np.ndarray
    max_height_m: float


@dataclass
class SwathPiece(PixelArrays):
    """One VIIRS granule prepared for collocation, with a KD-tree of its pixel blocks' centres."""

    tree: cKDTree
    tree_rows: np.ndarray
    tree_cols: np.ndarray


@dataclass
class ViirsSwath(PixelArrays):
    """One or more consecutive prepared granules stacked along rows; the pieces keep their KD-trees."""

    pieces: list

    @property
    def shape(self):
        return self.radiance.shape

    @classmethod
    def from_pieces(cls, pieces: list[SwathPiece]) -> "ViirsSwath":
        def cat(name):
            return (
                np.concatenate([getattr(p, name) for p in pieces])
                if len(pieces) > 1
                else getattr(pieces[0], name)
            )

        stacked = [
            cat(name) for name in ("ecef_m", "radiance", "area_vec_m2", "block_centre_m", "block_radius_m")
        ]
        return cls(
            *stacked,
            pieces[0].col_spacing_m,
            np.nanmean([p.advance_m for p in pieces], axis=0),
            pieces[0].det_step_m,
            max(p.max_height_m for p in pieces),
            list(pieces),
        )

    def nearest(self, points_m):
        """(row, col) of the first pixel of the usable block whose centre lies nearest each ECEF point."""
        best = np.full(len(points_m), np.inf)
        row = np.zeros(len(points_m), np.intp)
        col = np.zeros(len(points_m), np.intp)
        offset = 0
        for p in self.pieces:
            dist, idx = p.tree.query(points_m)
            better = dist < best
            best[better] = dist[better]
            row[better] = p.tree_rows[idx[better]] + offset
            col[better] = p.tree_cols[idx[better]]
            offset += p.radiance.shape[0]
        return row, col


def _half_diff(p, axis):
    """Half the difference of the two neighbours along *axis*, one-sided where a neighbour is missing."""
    fwd = np.full_like(p, np.nan)
    bwd = np.full_like(p, np.nan)
    n = p.shape[axis]
    a, b = [slice(None)] * p.ndim, [slice(None)] * p.ndim
    a[axis], b[axis] = slice(0, n - 1), slice(1, n)
    np.subtract(p[tuple(b)], p[tuple(a)], out=fwd[tuple(a)])
    bwd[tuple(b)] = fwd[tuple(a)]
    both = (fwd + bwd) * 0.5
    return np.where(np.isfinite(both), both, np.where(np.isfinite(fwd), fwd, bwd))


def _block_reduce(ufunc, p):
    """*ufunc* (np.fmin or np.fmax) over each B x B block of p (rows, cols, 3), as strided pairwise steps."""
    for axis in (0, 1):
        parts = [p[(slice(None),) * axis + (slice(k, None, BLOCK_PX),)] for k in range(BLOCK_PX)]
        p = parts[0]
        for q in parts[1:]:
            p = ufunc(p, q)
    return p


def _blocks(pos, usable):
    """Centre (float64 (rows/B, cols/B, 3), m) and radius (m) of a sphere holding the usable pixels of each
    B x B block: the centre and half diagonal of their bounding box.

    *pos* (rows, cols, 3) float32 ECEF of pixels, *usable* (rows, cols); rows are a multiple of B (whole
    scans), columns are padded. Blocks without a usable pixel get NaN, which fails every later test.
    """
    cols = usable.shape[1]
    p = np.pad(
        np.where(usable[..., None], pos, np.float32(np.nan)),
        ((0, 0), (0, -cols % BLOCK_PX), (0, 0)),
        constant_values=np.nan,
    )
    lo = _block_reduce(np.fmin, p).astype(np.float64)  # fmin and fmax skip NaN
    hi = _block_reduce(np.fmax, p).astype(np.float64)
    return (lo + hi) / 2, np.linalg.norm(hi - lo, axis=-1) / 2 + 1.0  # 1 m for the float32 rounding


def _scan_ends(scan):
    """First and last valid detector positions (float64, (cols, 3)) of one scan (32, cols, 3) and its step."""
    valid = np.isfinite(scan[..., 0])
    first = np.argmax(valid, axis=0)
    last = DETECTORS - 1 - np.argmax(valid[::-1], axis=0)
    cols = np.arange(scan.shape[1])
    p_first = scan[first, cols].astype(np.float64)
    p_last = scan[last, cols].astype(np.float64)
    step = np.linalg.norm(p_last - p_first, axis=-1) / np.maximum(last - first, 1)
    return p_first, p_last, step


def _scan_share(scan, ends, k):
    """The share (0.5..1) of each pixel's footprint of scan k (32, cols, 3) that is its own: where a
    neighbouring scan covers part of the footprint along track, that part is shared between two pixels.

    Along the track each pixel spans one detector step centred on it, each neighbour its first-to-last
    valid detector span plus half a step each side; an overlap of a fraction f of the footprint leaves
    the pixel 1 - f / 2. (Counting whole pixels in or out instead leaves ~1 % too much weight in stripes
    at the scan edges near nadir, where the overlap is a fraction of a detector, and biases the in-track
    minimum there.) *ends* maps scan index to :func:`_scan_ends` output and may hold the neighbouring
    granules' scans.
    """
    p_first, p_last, step = ends[k]
    u = p_last - p_first
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    s_pix = np.einsum("dcx,cx->dc", scan - p_first.astype(np.float32), u.astype(np.float32))
    half = (step / 2).astype(np.float32)
    share = np.ones(scan.shape[:2], np.float32)
    for n in (k - 1, k + 1):
        if n in ends:
            lo = (np.einsum("cx,cx->c", ends[n][0] - p_first, u) - ends[n][2] / 2).astype(np.float32)
            hi = (np.einsum("cx,cx->c", ends[n][1] - p_first, u) + ends[n][2] / 2).astype(np.float32)
            overlap = np.minimum(s_pix + half, hi) - np.maximum(s_pix - half, lo)
            share -= np.clip(overlap / (2 * half), 0.0, 1.0) / 2
    return share


def swath_piece(lat_rad, lon_rad, height_m, bt_k, good, band, before=None, after=None) -> SwathPiece:
    """Prepare one VIIRS granule (rows of 32-detector scans) of geolocation and I5 BT for collocation.

    Pixels are the 3-D points (lat_rad, lon_rad, height_m) (height above the ellipsoid; zeros for the
    ellipsoid product). *band* (:class:`monitor.spectral.I5Band`) turns pixel BT into band radiance.
    *before* and *after* are optional (lat_rad, lon_rad, height_m) of the neighbouring granules' adjacent
    scan, so that the scan overlap at the granule's first and last scan is counted as inside a continuous
    swath. Work goes scan by scan: large temporaries are slow to allocate.
    """
    rows, cols = lat_rad.shape
    nscan = rows // DETECTORS
    pos = np.empty((rows, cols, 3), np.float32)  # NaN where the geolocation is fill
    radiance = np.empty((rows, cols), np.float32)
    for k in range(nscan):
        sl = slice(k * DETECTORS, (k + 1) * DETECTORS)
        pos[sl] = wgs84.geodetic_to_ecef(lat_rad[sl], lon_rad[sl], height_m[sl])
        radiance[sl] = band.radiance_from_bt(np.where(good[sl], bt_k[sl], np.nan))
    scan = pos.reshape(nscan, DETECTORS, cols, 3)
    ends = {k: _scan_ends(scan[k]) for k in range(nscan)}
    for k, halo in ((-1, before), (nscan, after)):
        if halo is not None:
            ends[k] = _scan_ends(wgs84.geodetic_to_ecef(*halo))
    area = np.empty((rows, cols, 3), np.float32)
    for k in range(nscan):
        sl = slice(k * DETECTORS, (k + 1) * DETECTORS)
        cross = np.cross(_half_diff(scan[k], axis=1), _half_diff(scan[k], axis=0))
        area[sl] = cross * _scan_share(scan[k], ends, k)[..., None]
        bad = ~(np.isfinite(radiance[sl]) & np.all(np.isfinite(area[sl]), axis=-1))
        radiance[sl][bad] = np.nan
    located = np.isfinite(radiance)
    max_height = float(np.max(height_m[located])) if located.any() else 0.0

    mid = scan[nscan // 2]
    col_spacing = np.nanmedian(np.linalg.norm(_half_diff(mid, axis=1), axis=-1), axis=0)
    det_step = np.nanmedian(np.linalg.norm(_half_diff(mid, axis=0), axis=-1), axis=0)
    if nscan > 1:
        advance = np.nanmedian(np.linalg.norm(scan[nscan // 2] - scan[nscan // 2 - 1], axis=-1), axis=0)
    else:
        advance = det_step * DETECTORS
    centre = np.empty((rows // BLOCK_PX, -(-cols // BLOCK_PX), 3))
    radius = np.empty(centre.shape[:2])
    for k in range(nscan):  # scan by scan: blocks never straddle two scans
        sl = slice(k * DETECTORS, (k + 1) * DETECTORS)
        bl = slice(k * DETECTORS // BLOCK_PX, (k + 1) * DETECTORS // BLOCK_PX)
        centre[bl], radius[bl] = _blocks(pos[sl], np.isfinite(radiance[sl]))
    r_idx, c_idx = np.nonzero(np.isfinite(radius))
    tree = cKDTree(centre[r_idx, c_idx])
    r_idx, c_idx = r_idx * BLOCK_PX, c_idx * BLOCK_PX
    return SwathPiece(
        pos,
        radiance,
        area,
        centre,
        radius,
        _fill_nan(col_spacing),
        _fill_nan(advance),
        _fill_nan(det_step),
        max(max_height, 0.0),
        tree,
        r_idx,
        c_idx,
    )


def build_swath(lat_rad, lon_rad, height_m, bt_k, good, band) -> ViirsSwath:
    """A :class:`ViirsSwath` from stacked rows of consecutive VIIRS scans (one piece)."""
    return ViirsSwath.from_pieces([swath_piece(lat_rad, lon_rad, height_m, bt_k, good, band)])


def _fill_nan(a):
    a = np.asarray(a, float)
    ok = np.isfinite(a)
    return np.interp(np.arange(len(a)), np.nonzero(ok)[0], a[ok]) if not ok.all() else a


def _window_half_sizes(swath: ViirsSwath, col0, range_m, cos_zen, rho):
    """Row and column half-widths of the search window around each FOV centre pixel.

    The centre is the pixel nearest the LOS's ellipsoid point; pixels on terrain of height h meet the
    LOS up to h tan(zenith) before it, so both widths grow by that relief displacement.
    """
    cz = np.maximum(cos_zen, 0.2)
    relief = swath.max_height_m * np.sqrt(1.0 - cz * cz) / cz
    d_track = rho * range_m + relief
    d_scan = rho * range_m / cz + relief
    adv = swath.advance_m[col0]
    det = swath.det_step_m[col0]
    overlap = np.clip(1.0 - adv / (DETECTORS * det), 0.0, 1.0)
    half_rows = np.ceil(d_track / (adv / DETECTORS) + DETECTORS * overlap + 8).astype(int)
    ncol = len(swath.col_spacing_m)
    lo = np.clip(col0 - 200, 0, ncol - 1)
    hi = np.clip(col0 + 200, 0, ncol - 1)
    spacing = np.array([swath.col_spacing_m[a : b + 1].min() for a, b in zip(lo, hi, strict=True)])
    half_cols = np.ceil(d_scan / spacing + 4).astype(int)
    return half_rows, half_cols


def cone_sums(
    swath: ViirsSwath,
    sat_m,
    sbf_to_ecef,
    alpha_rad,
    beta_rad,
    offsets_rad,
    kernel=TOP_HAT,
    fov_range_m=None,
    fov_cos_zen=None,
):
    """Weighted VIIRS radiance means and coverage in every perturbed cone of a batch of FOVs.

    sat_m (F, 3) and sbf_to_ecef (F, 3, 3) give each FOV's satellite position and SBF; alpha_rad,
    beta_rad (F,) its LOS angles; offsets_rad (2n+1,) the perturbation grid. Returns
    ``(radiance (F, m, m), coverage (F, m, m))``; radiance is NaN where a cone holds no pixel.
    """
    nf = len(alpha_rad)
    m = len(offsets_rad)
    step = offsets_rad[1] - offsets_rad[0]
    n = (m - 1) // 2
    h_max = max(h for h, _ in kernel)
    rho = h_max + np.abs(offsets_rad).max() * np.sqrt(2.0) * 1.02
    los0 = np.einsum(
        "fij,fj->fi", sbf_to_ecef, np.stack([np.tan(alpha_rad), np.tan(beta_rad), np.ones(nf)], -1)
    )
    los0 /= np.linalg.norm(los0, axis=-1, keepdims=True)
    t = wgs84.intersect_ellipsoid(sat_m, los0)
    centre = sat_m + t[:, None] * los0
    ok_fov = np.isfinite(t)
    row0, col0 = swath.nearest(np.where(ok_fov[:, None], centre, 0.0))
    rng = fov_range_m if fov_range_m is not None else t
    cz = fov_cos_zen if fov_cos_zen is not None else np.abs(np.sum(wgs84.geodetic_up(centre) * los0, -1))
    hr, hc = _window_half_sizes(swath, col0, np.where(ok_fov, rng, 1e6), np.where(ok_fov, cz, 1.0), rho)
    # Candidates: the pixel blocks of the search window that can reach within rho of the LOS.
    R, C = int(hr.max()) // BLOCK_PX + 1, int(hc.max()) // BLOCK_PX + 1
    nbr, nbc = swath.block_radius_m.shape
    rr = row0[:, None] // BLOCK_PX + np.arange(-R, R + 1)
    cc = col0[:, None] // BLOCK_PX + np.arange(-C, C + 1)
    inside = ((rr >= 0) & (rr < nbr))[:, :, None] & ((cc >= 0) & (cc < nbc))[:, None, :]
    flat = np.clip(rr, 0, nbr - 1)[:, :, None] * nbc + np.clip(cc, 0, nbc - 1)[:, None, :]
    f_idx, w_idx = np.nonzero((inside & ok_fov[:, None, None]).reshape(nf, -1))
    blk = flat.reshape(nf, -1)[f_idx, w_idx]
    vec = swath.block_centre_m.reshape(-1, 3)[blk] - sat_m[f_idx]
    dist = np.linalg.norm(vec, axis=-1)
    radius = swath.block_radius_m.reshape(-1)[blk]
    with np.errstate(invalid="ignore"):
        reach = rho * 1.01 + np.arcsin(np.minimum(radius / dist, 1.0))  # angle of LOS to a pixel of the block
        near = np.einsum("kx,kx->k", vec, los0[f_idx]) >= dist * np.cos(np.minimum(reach, np.pi))
    f_idx, blk = f_idx[near], blk[near]
    b_row, b_col = np.divmod(blk, nbc)
    nrow, ncol = swath.shape
    r_pix = (b_row * BLOCK_PX)[:, None, None] + np.arange(BLOCK_PX)[:, None]
    c_pix = np.minimum((b_col * BLOCK_PX)[:, None, None] + np.arange(BLOCK_PX), ncol - 1)
    pix = (r_pix * ncol + c_pix).reshape(-1)
    f_idx = np.repeat(f_idx, BLOCK_PX * BLOCK_PX)
    usable = np.isfinite(swath.radiance.reshape(-1)[pix])
    if ncol % BLOCK_PX:  # the padded last block column repeats the last pixel column: count it once
        usable &= np.broadcast_to(
            (b_col * BLOCK_PX)[:, None, None] + np.arange(BLOCK_PX) < ncol,
            r_pix.shape[:1] + (BLOCK_PX, BLOCK_PX),
        ).reshape(-1)
    f_idx, pix = f_idx[usable], pix[usable]
    pos32 = swath.ecef_m.reshape(-1, 3)[pix]
    vec = pos32.astype(np.float64)
    vec -= sat_m[f_idx]
    # Pixel directions in each FOV's SBF (unnormalised); the pixels come sorted by FOV.
    bounds = np.searchsorted(f_idx, np.arange(nf + 1))
    d = np.empty_like(vec)
    for f in np.flatnonzero(np.diff(bounds)):
        np.matmul(vec[bounds[f] : bounds[f + 1]], sbf_to_ecef[f], out=d[bounds[f] : bounds[f + 1]])
    # The union of the perturbed cones is a rounded rectangle in (alpha, beta): drop what lies outside,
    # comparing tangents (d_z > 0 within rho of the LOS).
    half_a = np.abs(offsets_rad).max() + 1.02 * h_max / np.cos(beta_rad)
    half_b = np.abs(offsets_rad).max() + 1.02 * h_max
    tan_lim = np.tan(np.stack([alpha_rad - half_a, alpha_rad + half_a, beta_rad - half_b, beta_rad + half_b]))
    lim = tan_lim[:, f_idx] * d[:, 2]
    in_box = (d[:, 0] >= lim[0]) & (d[:, 0] <= lim[1]) & (d[:, 1] >= lim[2]) & (d[:, 1] <= lim[3])
    f_idx, pix, vec, d = f_idx[in_box], pix[in_box], vec[in_box], d[in_box]
    dist2 = np.einsum("kx,kx->k", vec, vec)
    dist = np.sqrt(dist2)
    d /= dist[:, None]
    area = swath.area_vec_m2.reshape(-1, 3)[pix]
    weight = np.abs(np.einsum("kx,kx->k", area, vec)) / (dist2 * dist)  # steradians seen from CrIS
    value = swath.radiance.reshape(-1)[pix].astype(np.float64)

    tan_a = np.tan(offsets_rad[:, None] + alpha_rad[None, :])  # (m, F)
    width = m + 2 * PAD  # runs may start or end off the grid; the margin keeps them in their own row
    size = nf * m * width
    acc = np.zeros(2 * size)  # weighted radiance sums, then weight sums, as difference arrays along j
    solid = 0.0
    rows = (np.arange(m)[:, None] * width).astype(np.float64)
    shift_f = n + PAD - beta_rad / step
    for h, c_k in kernel:
        g2 = np.cos(h) ** 2
        g2k = g2 * (1.0 + tan_a * tan_a)
        wv = weight * value * c_k
        wk = weight * c_k
        for b0 in range(0, len(f_idx), BLOCK):  # blocks small enough to stay in cache
            blk = slice(b0, b0 + BLOCK)
            fb = f_idx[blk]
            lo, hi = _j_intervals(d[blk], tan_a[:, fb], g2k[:, fb], g2, 1.0 / step, shift_f[fb])
            base = rows + (fb * (m * width)).astype(np.float64)
            np.clip(lo, 0, width - 1, out=lo)
            np.clip(hi, 0, width - 1, out=hi)
            lo += base
            hi += base
            start = lo.astype(np.intp).ravel()
            stop = hi.astype(np.intp).ravel()
            for off, val in ((0, wv[blk]), (size, wk[blk])):
                v = np.broadcast_to(val, lo.shape).ravel()
                acc[off : off + size] += np.bincount(start, v, size) - np.bincount(stop, v, size)
        solid += c_k * 2 * np.pi * (1 - np.cos(h))
    acc = np.cumsum(acc.reshape(2, nf, m, width), axis=-1)[..., PAD : PAD + m]
    sums, wsum = acc[0], acc[1]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(wsum > 0, sums / wsum, np.nan)
    return mean, wsum / solid


def _j_intervals(d, tan_a, g2k, g2, scale, shift):
    """Run start and stop per row i and pixel, float arrays (m, N) of j + PAD; start = stop when empty.

    Solves (c + dy t)^2 >= g2 (K + t^2) with c = dx tan A_i + dz, K = 1 + tan^2 A_i, t = tan B_j and
    g2 = cos^2 h: the solution in t is one interval, and B_j = beta + (j - n) s gives the j run.
    *g2k* is g2 K (m, N); *scale* is 1/s and *shift* n + PAD - beta/s per pixel. The quadratic needs
    float64 throughout (float32 would misplace pixels within 0.05 urad of a cone edge). Rows come first
    so that every operation runs over the long pixel axis.
    """
    dx, dy, dz = d[:, 0], d[:, 1], d[:, 2]
    a2 = dy * dy - g2
    c = tan_a * dx
    c += dz
    b1 = c * dy
    disc = c * c
    disc -= g2k
    disc *= -a2
    disc += b1 * b1
    np.maximum(disc, 0.0, out=disc)
    sq = np.sqrt(disc, out=disc)
    inv_a2 = 1.0 / a2
    lo = np.subtract(sq, b1, out=c)
    lo *= inv_a2
    hi = np.add(b1, sq, out=b1)
    hi *= -inv_a2
    lo = np.arctan(lo, out=lo)
    hi = np.arctan(hi, out=hi)
    lo *= scale
    lo += shift
    hi *= scale
    hi += shift
    np.ceil(lo, out=lo)
    np.floor(hi, out=hi)
    hi += 1
    return lo, hi
