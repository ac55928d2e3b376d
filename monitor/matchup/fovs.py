"""Where each CrIS FOV looks and how it weighs the scene: its line of sight and its spatial response.

Placed on the operational geolocation, a FOV's line of sight is the GEO product's (the inverse
geolocation, :func:`monitor.geometry.inverse.granule_geometry`). Placed on the assessed geolocation, it is
turned by its FOR's offsets: alpha and beta (equations 1-2 of Wang et al. 2017, in the spacecraft body
frame) grow by ``d_alpha_urad`` and ``d_beta_urad``, the correction the assessment reports
(docs/reading-results.md). Its ground point is then where the turned line of sight meets the ellipsoid.

The response is the nominal one (:data:`monitor.instrument.footprint.DEFAULT_SHAPE`) or, where a day's
assessment fitted one, a super-Gaussian through the FOR's fitted full widths at 50 and 10 % of the peak:
exp(-ln 2 (r / r50)^n), n = ln(ln 10 / ln 2) / ln(w10 / w50).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from monitor.collocation.collocate import los_ecef
from monitor.core.constants import N_FOR, URAD
from monitor.core.result import ForOffset
from monitor.geometry import wgs84
from monitor.geometry.inverse import granule_geometry
from monitor.instrument.footprint import DEFAULT_SHAPE, RadialResponse, shape, super_gaussian
from monitor.matchup.weighted import TABLE_SAMPLES
from monitor.sdr.granules import CrisGeoGranule

NOMINAL_ORDER = 10.0  # the nominal super-Gaussian's order: the order a FOR without a fitted 10 % width keeps


@dataclass(frozen=True)
class PlacedFovs:
    """A CrIS granule's FOVs as the mapping places them; leading shape (nscan, 30, 9).

    ``sat_m`` the CrIS position and ``los`` the unit line of sight (ECEF), ``lat_rad``/``lon_rad`` the
    ground point, ``valid`` where the GEO has every field.
    """

    sat_m: np.ndarray
    los: np.ndarray
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    zenith_rad: np.ndarray
    range_m: np.ndarray
    valid: np.ndarray


def place(geo: CrisGeoGranule, offsets: Sequence[ForOffset] | None = None) -> PlacedFovs:
    """Place a granule's FOVs: on the operational geolocation, or turned by each FOR's assessed offsets.

    Parameters
    ----------
    geo : CrisGeoGranule
        The granule's GEO.
    offsets : sequence of ForOffset, optional
        The day's 30 FORs (``crisgeo assess --out``); a FOR whose offsets are not finite stays where GEO
        puts it.

    Returns
    -------
    PlacedFovs
        The FOVs.
    """
    g = granule_geometry(geo)
    alpha, beta = g.alpha_rad, g.beta_rad
    if offsets is not None:
        da = np.array([o.d_alpha_urad for o in offsets], float) * URAD
        db = np.array([o.d_beta_urad for o in offsets], float) * URAD
        da, db = np.nan_to_num(da), np.nan_to_num(db)
        alpha, beta = alpha + da[None, :, None], beta + db[None, :, None]
    shape3 = alpha.shape
    los = los_ecef(g.sbf_to_ecef.reshape(-1, 3, 3), alpha.ravel(), beta.ravel()).reshape(shape3 + (3,))
    sat = np.broadcast_to(g.sat_ecef_m, shape3 + (3,))
    if offsets is None:
        lat, lon = geo.lat_rad, geo.lon_rad
    else:
        t = wgs84.intersect_ellipsoid(sat, los)
        lat, lon, _ = wgs84.ecef_to_geodetic(sat + t[..., None] * los)
    return PlacedFovs(
        np.ascontiguousarray(sat),
        los,
        lat,
        lon,
        geo.zenith_rad,
        np.linalg.norm(sat - g.ground_ecef_m, axis=-1),
        geo.valid,
    )


@dataclass(frozen=True)
class Responses:
    """The responses the FOVs weigh pixels with: tabulated (``tables``, uniform in angle to ``reach_rad``),
    with each one's integral over the solid angle (``norm_sr``) and the table of each FOR (``of_for``)."""

    tables: np.ndarray
    reach_rad: np.ndarray
    norm_sr: np.ndarray
    of_for: np.ndarray
    fitted: bool


def _table(response: RadialResponse) -> tuple[np.ndarray, float, float]:
    reach = float(response.reach_rad)
    r = np.linspace(0.0, reach, TABLE_SAMPLES)
    values = np.asarray(response(r), float)
    f = values * np.sin(r)
    norm = float(2 * math.pi * np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(r)))  # the trapezoid rule
    return values, reach, norm


def responses(offsets: Sequence[ForOffset] | None = None) -> Responses:
    """The nominal response for every FOR, or the day's fitted one per FOR where *offsets* carry widths.

    Parameters
    ----------
    offsets : sequence of ForOffset, optional
        The day's 30 FORs.

    Returns
    -------
    Responses
        One table per distinct response.
    """
    nominal = shape(DEFAULT_SHAPE)
    assert isinstance(nominal, RadialResponse)  # the default shape is radially symmetric
    each: list[RadialResponse] = [nominal] * N_FOR
    fitted = False
    for k, o in enumerate(offsets or ()):
        w50, w10 = o.response_width_50_urad * URAD, o.response_width_10_urad * URAD
        if not (np.isfinite(w50) and w50 > 0):
            continue
        order = math.log(math.log(10) / math.log(2)) / math.log(w10 / w50) if w10 > w50 else NOMINAL_ORDER
        each[k] = super_gaussian(order=min(max(order, 2.0), 40.0), half_width_50_rad=w50 / 2)
        fitted = True
    unique = list(dict.fromkeys(each))
    rows = [_table(r) for r in unique]
    return Responses(
        np.array([r[0] for r in rows]),
        np.array([r[1] for r in rows]),
        np.array([r[2] for r in rows]),
        np.array([unique.index(r) for r in each], np.int64),
        fitted,
    )
