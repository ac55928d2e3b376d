"""Geolocate CrIS GEO granules with an EP: compare with the files' own fields, or write new files.

The role ADL plays in section 4.2 of the paper: the same spacecraft ephemeris and attitude as the
file, the CrIS LOS from another EP. Inputs are never modified; a regeolocated file is a copy whose
Latitude, Longitude, SatelliteZenithAngle, SatelliteAzimuthAngle and SatelliteRange are rewritten
(fill values kept where the input had them) and whose granule bounding coordinates follow.
Height and the solar angles are left as they were (a shift of a few km changes them by less than
their precision), and the file records the EP used in the attribute ``crisgeo_engineering_packet``.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from monitor.core.constants import N_FOR
from monitor.core.errors import DataError
from monitor.geometry import ep_model, wgs84
from monitor.geometry.ep_model import EngineeringPacket
from monitor.geometry.geolocate import GroundView, geolocate_fovs
from monitor.mapping.residuals import OwnResiduals, ResidualTable
from monitor.sdr import read_file
from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import CrisGeoGranule
from monitor.sdr.products import PRODUCTS

GEO = PRODUCTS["GCRSO"]
_REWRITTEN = {
    "Latitude": ("lat_rad", np.degrees),
    "Longitude": ("lon_rad", np.degrees),
    "SatelliteZenithAngle": ("zenith_rad", np.degrees),
    "SatelliteAzimuthAngle": ("azimuth_rad", np.degrees),
    "SatelliteRange": ("range_m", None),
}


def geolocate_granule(
    ep: EngineeringPacket, g: CrisGeoGranule, residuals: ResidualTable | OwnResiduals | None = None
) -> GroundView:
    """Geolocation of every FOV of *g* with the LOS of *ep* (turned by the per-FOR *residuals*, if given)
    and the granule's own ephemeris and attitude.

    Parameters
    ----------
    g : CrisGeoGranule
        The granule.
    ep : EngineeringPacket
        The EP to geolocate with.
    residuals : ResidualTable or OwnResiduals, optional
        The per-FOR FOV-5 residuals applied to the EP model.

    Returns
    -------
    GroundView
        The geolocation.
    """
    if g.meta.platform != ep.satellite:
        raise DataError(f"{g.meta.path}: granule of {g.meta.platform}, EP {ep.version} of {ep.satellite}")
    if residuals is not None and residuals.satellite != ep.satellite:
        raise DataError(f"residual table of {residuals.satellite}, EP {ep.version} of {ep.satellite}")
    los = ep_model.los_spacecraft(ep)
    if residuals is not None:
        los = residuals.table_for(g).apply(los)
    return geolocate_fovs(
        los, g.for_time_us, g.mid_time_us, g.sc_position_m, g.sc_velocity_m_s, g.sc_attitude_rad
    )


def _geo_granules(path: str | Path) -> list[CrisGeoGranule]:
    granules = read_file(path, kinds=("cris_geo",))
    if not granules:
        raise GranuleError(path, GEO.data_group, "no CrIS GEO granule in the file")
    return granules


@dataclass(frozen=True)
class ForDistance:
    """Distance (m) between the model's FOV centres and the file's, over all scans and FOVs of a FOR."""

    for_index: int
    n: int
    median_m: float
    p99_m: float
    max_m: float

    def to_dict(self) -> dict:
        return {
            "for": self.for_index,
            "n": self.n,
            "median_m": self.median_m,
            "p99_m": self.p99_m,
            "max_m": self.max_m,
        }


def compare_with_files(
    ep: EngineeringPacket, paths: Iterable[str | Path], residuals: ResidualTable | OwnResiduals | None = None
) -> list[ForDistance]:
    """Per-FOR statistics of the distance between *ep*'s geolocation (with *residuals*, if given) and the
    files' latitude/longitude.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
        CrIS GEO files.
    ep : EngineeringPacket
        The EP.
    residuals : ResidualTable or OwnResiduals, optional
        The per-FOR residuals.

    Returns
    -------
    list of ForDistance
        Per FOR the statistics of the distance from the files' own geolocation.
    """
    per_for: list[list] = [[] for _ in range(N_FOR)]
    for path in paths:
        for g in _geo_granules(path):
            view = geolocate_granule(ep, g, residuals)
            ref = wgs84.geodetic_to_ecef(g.lat_rad, g.lon_rad, 0.0)
            d = np.linalg.norm(view.ground_ecef_m - ref, axis=-1)
            for k in range(N_FOR):
                col = d[:, k].ravel()
                per_for[k].append(col[np.isfinite(col)])
    out = []
    for k, parts in enumerate(per_for):
        d = np.concatenate(parts) if parts else np.array([])
        if d.size == 0:
            out.append(ForDistance(k + 1, 0, float("nan"), float("nan"), float("nan")))
        else:
            out.append(
                ForDistance(
                    k + 1, int(d.size), float(np.median(d)), float(np.percentile(d, 99)), float(d.max())
                )
            )
    return out


def regeolocate_file(
    ep: EngineeringPacket,
    path: str | Path,
    out_dir: str | Path,
    residuals: ResidualTable | OwnResiduals | None = None,
) -> Path:
    """Write a copy of the GEO file *path* into *out_dir* with its geolocation computed from *ep* (and the
    per-FOR *residuals*, if given).

    Parameters
    ----------
    path : str or os.PathLike
        A CrIS GEO file.
    ep : EngineeringPacket
        The EP.
    out_dir : str or os.PathLike
        Where the copy goes (never the input's directory).
    residuals : ResidualTable or OwnResiduals, optional
        The per-FOR residuals.

    Returns
    -------
    Path
        The copy.
    """
    src = Path(path).resolve()
    dst_dir = Path(out_dir).resolve()
    if dst_dir == src.parent:
        raise DataError(f"{src}: the output directory is the input's; regeolocation never touches its inputs")
    granules = _geo_granules(src)
    dst_dir.mkdir(parents=True, exist_ok=True)
    dst = dst_dir / src.name
    tmp = dst.with_name(dst.name + ".part")
    shutil.copyfile(src, tmp)
    try:
        with h5py.File(tmp, "r+") as h5:
            group = h5[GEO.data_group]
            row = 0
            for k, g in enumerate(granules):
                view = geolocate_granule(ep, g, residuals)
                rows = slice(row, row + g.lat_rad.shape[0])
                row = rows.stop
                for dataset, (attr, convert) in _REWRITTEN.items():
                    dset = group[dataset]
                    old = dset[rows]
                    new = getattr(view, attr)
                    new = convert(new) if convert else new
                    keep = ~np.isfinite(new) | (old < -999.0)
                    dset[rows] = np.where(keep, old, new).astype(dset.dtype)
                _update_bounds(h5, k, view)
            group.attrs["crisgeo_engineering_packet"] = json.dumps(
                {
                    "version": ep.version,
                    "satellite": ep.satellite,
                    "provenance": ep.provenance,
                    "residuals": None
                    if residuals is None
                    else {"own_against": residuals.ep_in_force.version}
                    if isinstance(residuals, OwnResiduals)
                    else {"ep_version": residuals.ep_version, "granules": list(residuals.granules)},
                }
            )
        tmp.replace(dst)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return dst


def _update_bounds(h5: h5py.File, k: int, view: GroundView) -> None:
    name = f"Data_Products/{GEO.collection}/{GEO.collection}_Gran_{k}"
    if name not in h5 or not np.any(np.isfinite(view.lat_rad)):
        return
    a = h5[name].attrs
    lat, lon = np.degrees(view.lat_rad), np.degrees(view.lon_rad)
    for key, value in (
        ("North_Bounding_Coordinate", np.nanmax(lat)),
        ("South_Bounding_Coordinate", np.nanmin(lat)),
        ("East_Bounding_Coordinate", np.nanmax(lon)),
        ("West_Bounding_Coordinate", np.nanmin(lon)),
    ):
        if key in a:
            a[key] = (
                np.asarray(a[key]).dtype.type(value)
                if np.asarray(a[key]).ndim == 0
                else np.full(np.asarray(a[key]).shape, value, np.asarray(a[key]).dtype)
            )
