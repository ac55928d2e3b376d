"""One VIIRS band's granule made ready for the mapping: pixel points, BT and band radiance, where to look.

A granule is read once (its GEO once for every band of its grid), its pixels turned into ECEF points
(float32, 0.5 m resolution: 0.6 urad seen from CrIS), its BT into band radiance by the band model. A
KD-tree of every fourth pixel of every fourth row finds the pixel nearest a FOV's centre, and the
column and detector spacings of the granule's middle scan size the window of rows and columns the FOV
searches (:func:`windows`): its reach on the ground, range x tan(reach) / cos(view zenith), in pixels,
plus half a scan of rows for the overlap of consecutive scans towards the swath edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from monitor.geometry import wgs84
from monitor.instrument.spectral import band_model
from monitor.matchup.fovs import PlacedFovs
from monitor.sdr.granules import ViirsGeoGranule, ViirsSdrGranule

COARSE_PX = 4  # the KD-tree holds every 4th pixel of every 4th row
WINDOW_MARGIN_PX = 4  # beyond the reach: the coarse tree's nearest pixel is within 4 of the nearest one
FIND_WITHIN_M = 60e3  # a FOV whose centre lies farther than this from every pixel is not in the granule


@dataclass
class GridPixels:
    """A VIIRS granule's GEO on its grid: ECEF points (rows, cols, 3) float32, NaN where none, and the
    search aids (:mod:`monitor.matchup.swaths`)."""

    pix_m: np.ndarray
    detectors: int
    tree: cKDTree
    tree_rows: np.ndarray
    tree_cols: np.ndarray
    col_spacing_m: np.ndarray
    det_spacing_m: np.ndarray


@dataclass
class BandPixels:
    """One band of a VIIRS granule on its grid: BT (K) and band radiance (mW/(m2 sr cm-1)), shape
    (1, rows, cols), and where a pixel is usable."""

    band: str
    grid: GridPixels
    bt_k: np.ndarray
    radiance: np.ndarray
    good: np.ndarray


def _fill(a: np.ndarray) -> np.ndarray:
    ok = np.isfinite(a)
    if ok.all() or not ok.any():
        return a
    return np.interp(np.arange(len(a)), np.flatnonzero(ok), a[ok])


def grid_pixels(geo: ViirsGeoGranule, detectors: int) -> GridPixels:
    """Prepare a VIIRS GEO granule's pixels for the search.

    Parameters
    ----------
    geo : ViirsGeoGranule
        The granule's geolocation (its pixels at their 3-D points).
    detectors : int
        Rows per scan (32 I-band, 16 M-band).

    Returns
    -------
    GridPixels
        The ECEF points and the search aids.
    """
    assert geo.height_m is not None  # ViirsGeoGranule sets zeros where the product has no Height
    pix = wgs84.geodetic_to_ecef(geo.lat_rad, geo.lon_rad, geo.height_m).astype(np.float32)
    rows, cols = pix.shape[:2]
    sub = pix[::COARSE_PX, ::COARSE_PX]
    ok = np.isfinite(sub[..., 0])
    r_idx, c_idx = np.nonzero(ok)
    tree = cKDTree(sub[ok].astype(np.float64), leafsize=64, balanced_tree=False, compact_nodes=False)
    nscan = rows // detectors
    mid = pix[(nscan // 2) * detectors : (nscan // 2 + 1) * detectors].astype(np.float64)
    col_step = np.linalg.norm(np.diff(mid, axis=1), axis=-1)
    det_step = np.linalg.norm(np.diff(mid, axis=0), axis=-1)
    col_spacing = np.nanmedian(np.concatenate([col_step, col_step[:, -1:]], axis=1), axis=0)
    det_spacing = np.nanmedian(det_step, axis=0)
    return GridPixels(
        pix,
        detectors,
        tree,
        r_idx * COARSE_PX,
        c_idx * COARSE_PX,
        _fill(col_spacing),
        _fill(det_spacing),
    )


def band_pixels(sdr: ViirsSdrGranule, grid: GridPixels, band: str, satellite: str) -> BandPixels:
    """One band's pixels of a granule on its prepared grid.

    Parameters
    ----------
    sdr : ViirsSdrGranule
        The band's SDR granule.
    grid : GridPixels
        Its GEO, prepared.
    band : str
        I5, M13, M15 or M16.
    satellite : str
        The satellite (its band response).

    Returns
    -------
    BandPixels
        BT, band radiance and usable pixels.
    """
    if sdr.bt_k.shape != grid.pix_m.shape[:2]:
        raise ValueError(f"{band}: SDR shape {sdr.bt_k.shape}, its GEO {grid.pix_m.shape[:2]}")
    good = sdr.good & np.isfinite(grid.pix_m[..., 0])
    model = band_model(satellite, band)
    bt = np.where(good, sdr.bt_k, np.nan).astype(np.float32)
    radiance = model.radiance_from_bt(bt).astype(np.float32)
    good &= np.isfinite(radiance)
    return BandPixels(band, grid, bt[None], radiance[None], good[None])


def windows(grid: GridPixels, fovs: PlacedFovs, reach_rad: float) -> np.ndarray:
    """Each FOV's window of rows and columns, [r0, r1) x [c0, c1); empty where the FOV is not in the granule.

    Parameters
    ----------
    grid : GridPixels
        The granule's pixels.
    fovs : PlacedFovs
        The FOVs, flattened to (F,) by the caller's order.
    reach_rad : float
        The widest response's reach, rad.

    Returns
    -------
    numpy.ndarray
        int64, shape (F, 4).
    """
    ground = wgs84.geodetic_to_ecef(fovs.lat_rad.ravel(), fovs.lon_rad.ravel(), 0.0)
    ok = fovs.valid.ravel() & np.all(np.isfinite(ground), axis=-1)
    out = np.zeros((ok.size, 4), np.int64)
    if not ok.any():
        return out
    dist, idx = grid.tree.query(np.where(ok[:, None], ground, 0.0), distance_upper_bound=FIND_WITHIN_M)
    found = ok & np.isfinite(dist)
    idx = np.where(found, idx, 0)
    r, c = grid.tree_rows[idx], grid.tree_cols[idx]
    cos_z = np.maximum(np.cos(fovs.zenith_rad.ravel()), 0.2)
    reach_m = fovs.range_m.ravel() * math.tan(reach_rad) / cos_z
    half_c = np.ceil(reach_m / grid.col_spacing_m[c]).astype(np.int64) + WINDOW_MARGIN_PX
    half_r = (
        np.ceil(reach_m / grid.det_spacing_m[c]).astype(np.int64) + grid.detectors // 2 + WINDOW_MARGIN_PX
    )
    rows, cols = grid.pix_m.shape[:2]
    out[:, 0] = np.clip(r - half_r, 0, rows)
    out[:, 1] = np.clip(r + half_r + 1, 0, rows)
    out[:, 2] = np.clip(c - half_c, 0, cols)
    out[:, 3] = np.clip(c + half_c + 1, 0, cols)
    out[~found] = 0
    return out
