"""VIIRS pixels placed at the height of what they see: the parallax of clouds with height.

GEO puts every VIIRS pixel where its line of sight meets the terrain. A cloud top H above it is seen along
the same line, so the point VIIRS saw is the GEO point moved back up its line of sight by H / cos(z) (z the
view zenith angle there). CrIS sees the same cloud from another angle: its rows ahead (FOVs 7-9) look
19.1 mrad forward, its rows behind 19.1 mrad back, VIIRS within 7 mrad of the scan plane. Seen from CrIS,
the GEO point and the cloud differ by ~23 urad per km of height for an outer row at nadir. With every pixel
at its 3-D point, each CrIS cone meets the scene where it is, whatever angle it looks from
(:mod:`monitor.collocation.collocate` tests angles from the CrIS spacecraft to 3-D points).

How high. A cloud's top is colder than the clear surface around it by about its height times the lapse rate
(times the window channel's transmittance, which shrinks BT contrasts). Each pixel is lifted by

    H = kappa * max(T_ref - BT, 0),

where T_ref is the neighbourhood's clear-sky reference: the warmest BT within +-:data:`REFERENCE_HALF_PX`
pixels (~15 km; a 3 x 3 mean first, so that one noisy pixel does not set it). kappa (m per K) is not
assumed: the assessment collocates at kappa = 0 and at :data:`PROBE_M_PER_K`, and chooses the day's kappa
from its own cost (:mod:`monitor.estimation.parallax`).

Where the pixel's line of sight comes from. The spacecraft position of each scan (GEO's SCPosition, at the
scan's middle) moves ~2 km over the Earth view, which would turn the line by ~1 mrad at the swath's edge;
each pixel's own position is the scan's plus the velocity times its time from the middle, which is its scan
angle over VIIRS's rotation rate (one turn per scan period).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import maximum_filter, uniform_filter

from monitor.core.constants import VIIRS_DETECTORS, VIIRS_SCAN_US
from monitor.geometry import wgs84

REFERENCE_HALF_PX = 40  # +-40 pixels: ~15 km at nadir, wider than a CrIS cone's reach from its edge
PROBE_M_PER_K = 180.0  # the second collocation's lift: 6.5 K/km seen through a window transmittance ~0.85
ROTATION_RAD_S = 2.0 * math.pi / (VIIRS_SCAN_US * 1e-6)


def reference_k(bt_k: np.ndarray, good: np.ndarray) -> np.ndarray:
    """The clear-sky reference BT (K) around each pixel of *bt_k* (rows, cols): the warmest 3 x 3 mean
    within +-REFERENCE_HALF_PX pixels (unusable pixels never set it; NaN where none is usable)."""
    ok = good & np.isfinite(bt_k)
    filled = np.where(ok, bt_k, 0.0).astype(np.float32)
    count = uniform_filter(ok.astype(np.float32), 3, mode="nearest")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0.5, uniform_filter(filled, 3, mode="nearest") / count, -np.inf)
    ref = maximum_filter(mean, size=2 * REFERENCE_HALF_PX + 1, mode="nearest")
    return np.where(np.isfinite(ref), ref, np.nan).astype(np.float32)


def lift_m(bt_k: np.ndarray, good: np.ndarray, m_per_k: float) -> np.ndarray:
    """Each pixel's height (m) above its GEO point: *m_per_k* times how much colder than the clear-sky
    reference it is (0 where unusable)."""
    if m_per_k == 0.0:
        return np.zeros(bt_k.shape, np.float32)
    cooling = np.nan_to_num(reference_k(bt_k, good) - bt_k, nan=0.0)
    return np.where(good, m_per_k * np.maximum(cooling, 0.0), 0.0).astype(np.float32)


def lifted(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    lift: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lat_rad, lon_rad, height_m) of the pixels (rows of 32-detector scans, cols) moved back up their
    lines of sight by *lift* (m, above the GEO point) / cos(view zenith), from the spacecraft at each
    pixel's time (scan *sat_m* and *velocity_m_s* (nscan, 3), ECEF, at the scan's middle). Computed in
    float64, returned in float32: the swath keeps its points in float32 (0.5 m), and a granule's three
    float64 copies would be 240 MB more at the collocation's peak."""
    lat, lon, h = (np.array(a, np.float32) for a in (lat_rad, lon_rad, height_m))
    for k in range(lat.shape[0] // VIIRS_DETECTORS):
        rows = slice(k * VIIRS_DETECTORS, (k + 1) * VIIRS_DETECTORS)
        up = lift[rows] > 0
        if not up.any() or not np.all(np.isfinite(sat_m[k])):
            continue
        r, c = np.nonzero(up)
        la, lo, hh = (np.asarray(a[rows][r, c], np.float64) for a in (lat_rad, lon_rad, height_m))
        p = wgs84.geodetic_to_ecef(la, lo, hh)
        s, v = np.asarray(sat_m[k], float), np.asarray(velocity_m_s[k], float)
        nadir = -s / np.linalg.norm(s)
        across = np.cross(v, s)
        across /= np.linalg.norm(across)
        los = p - s
        angle = np.arctan2(los @ across, los @ nadir)  # the scan angle, its sign by the cross-track side
        order = np.sign(np.polyfit(c, angle, 1)[0]) if np.ptp(c) > 0 else 1.0  # columns come in time order
        sat = s + v * (order * angle / ROTATION_RAD_S)[:, None]
        view = sat - p
        view /= np.linalg.norm(view, axis=1, keepdims=True)
        normal = np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], -1)
        x = p + (lift[rows][r, c] / np.sum(view * normal, axis=1))[:, None] * view
        new = wgs84.ecef_to_geodetic(x, 3)
        for a, b in zip((lat, lon, h), new, strict=True):
            a[rows][r, c] = b
    return lat, lon, h
