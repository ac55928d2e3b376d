"""Read IDPS HDF5 files (single, aggregated or combined) into one typed object per granule.

A file may hold several products (``GCRSO-SCRIF_...``: one ``All_Data/<coll>_All`` group each) and
several granules concatenated on axis 0 (scans per granule from ``_Gran_k/N_Number_Of_Scans``; VIIRS
always reserves 48 scans). Every problem is raised as :class:`GranuleError` naming file and field.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from monitor.sdr.errors import GranuleError
from monitor.sdr.iet import iet_to_datetime
from monitor.sdr.names import parse_name
from monitor.sdr.products import PRODUCTS, is_float_fill, UINT16_FILL_MIN, Product, cris_lw_wavenumbers_cm1


@dataclass(frozen=True)
class GranuleMeta:
    """What identifies a granule and what produced it (from the ``_Gran_k`` attributes)."""

    path: str
    product: str
    collection: str
    platform: str  # npp, j01, j02
    granule_id: str
    orbit: int
    start: dt.datetime
    end: dt.datetime
    start_iet_us: int
    end_iet_us: int
    n_scans: int
    ascending: bool | None
    software_version: str
    algorithm_version: str
    aux_files: tuple[str, ...]
    anc_files: tuple[str, ...]

    def to_dict(self) -> dict:
        d = dict(self.__dict__)
        d["start"] = self.start.isoformat()
        d["end"] = self.end.isoformat()
        d["aux_files"] = list(self.aux_files)
        d["anc_files"] = list(self.anc_files)
        return d


@dataclass
class CrisGeoGranule:
    """CrIS GEO arrays of one granule; FOV fields (nscan, 30, 9), per-FOR times (nscan, 30)."""

    meta: GranuleMeta
    for_time_us: np.ndarray
    start_time_us: np.ndarray
    mid_time_us: np.ndarray
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    height_m: np.ndarray
    range_m: np.ndarray
    zenith_rad: np.ndarray
    azimuth_rad: np.ndarray
    sc_position_m: np.ndarray
    sc_velocity_m_s: np.ndarray
    sc_attitude_rad: np.ndarray

    @property
    def valid(self) -> np.ndarray:
        """FOVs whose every geometry field is present."""
        ok = np.ones(self.lat_rad.shape, bool)
        for a in (self.lat_rad, self.lon_rad, self.range_m, self.zenith_rad, self.azimuth_rad):
            ok &= np.isfinite(a)
        scan_ok = np.all(np.isfinite(self.sc_position_m) & np.isfinite(self.sc_velocity_m_s)
                         & np.isfinite(self.sc_attitude_rad), axis=1)
        return ok & scan_ok[:, None, None] & (self.for_time_us > 0)[:, :, None]


@dataclass
class CrisSdrGranule:
    """CrIS long-wave radiances (nscan, 30, 9, nchan) in mW/(m2 sr cm-1) and their quality."""

    meta: GranuleMeta
    wavenumber_cm1: np.ndarray
    radiance_lw: np.ndarray
    qf3: np.ndarray
    qf1_scan: np.ndarray | None

    @property
    def good(self) -> np.ndarray:
        """FOVs with good LW SDR quality (``QF3 & 0b11 == 0``, Wang's rule) and finite spectra."""
        ok = (self.qf3[..., 0] & 0b11) == 0
        return ok & np.all(np.isfinite(self.radiance_lw), axis=-1)


@dataclass
class ViirsSdrGranule:
    """VIIRS I5 brightness temperature (rows, 6400) in K, NaN where filled (bow-tie deletion included)."""

    meta: GranuleMeta
    bt_k: np.ndarray
    qf1: np.ndarray

    @property
    def good(self) -> np.ndarray:
        """Pixels with a value and QF1 == 0 (Wang's rule)."""
        return np.isfinite(self.bt_k) & (self.qf1 == 0)


@dataclass
class ViirsGeoGranule:
    """VIIRS I-band geolocation (rows, 6400) and per-scan spacecraft state.

    Each pixel is the 3-D point (lat_rad, lon_rad, height_m): GITCO gives the terrain height where the
    pixel's line of sight meets the terrain, GIMGO (ellipsoid geolocation) has no Height and its pixels
    are at h = 0 (``height_m`` zeros).
    """

    meta: GranuleMeta
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    start_time_us: np.ndarray
    mid_time_us: np.ndarray
    sc_position_m: np.ndarray
    sc_velocity_m_s: np.ndarray
    sc_attitude_rad: np.ndarray
    height_m: np.ndarray | None = None

    def __post_init__(self):
        if self.height_m is None:
            self.height_m = np.zeros_like(self.lat_rad)


_GRANULE_TYPES = {"cris_geo": CrisGeoGranule, "cris_sdr": CrisSdrGranule, "viirs_sdr": ViirsSdrGranule,
                  "viirs_geo": ViirsGeoGranule}


def _text(value) -> str:
    a = np.asarray(value).ravel()
    v = a[0] if a.size else b""
    return v.decode("ascii", "replace").strip() if isinstance(v, bytes) else str(v)


def _texts(value) -> tuple[str, ...]:
    if value is None:
        return ()
    return tuple(v.decode("ascii", "replace").strip() if isinstance(v, bytes) else str(v)
                 for v in np.asarray(value).ravel())


def _when(date: str, time: str) -> dt.datetime:
    t = time.rstrip("Z")
    return dt.datetime.strptime(f"{date} {t}", "%Y%m%d %H%M%S.%f").replace(tzinfo=dt.timezone.utc)


def _granule_meta(path: Path, h5: h5py.File, product: Product, k: int, platform: str) -> GranuleMeta:
    name = f"Data_Products/{product.collection}/{product.collection}_Gran_{k}"
    if name not in h5:
        raise GranuleError(path, name, "missing granule metadata")
    a = h5[name].attrs
    try:
        start_iet = int(np.asarray(a["N_Beginning_Time_IET"]).ravel()[0])
        end_iet = int(np.asarray(a["N_Ending_Time_IET"]).ravel()[0])
        n_scans = int(np.asarray(a["N_Number_Of_Scans"]).ravel()[0])
    except KeyError as exc:
        raise GranuleError(path, f"{name}/{exc.args[0]}", "missing attribute") from None
    try:
        start = _when(_text(a["Beginning_Date"]), _text(a["Beginning_Time"]))
        end = _when(_text(a["Ending_Date"]), _text(a["Ending_Time"]))
    except (KeyError, ValueError):
        start, end = iet_to_datetime(start_iet), iet_to_datetime(end_iet)
    asc = a.get("Ascending/Descending_Indicator")
    return GranuleMeta(
        path=str(path), product=product.prefix, collection=product.collection, platform=platform,
        granule_id=_text(a.get("N_Granule_ID", b"")), orbit=int(np.asarray(a.get("N_Beginning_Orbit_Number", 0)).ravel()[0]),
        start=start, end=end, start_iet_us=start_iet, end_iet_us=end_iet, n_scans=n_scans,
        ascending=None if asc is None else int(np.asarray(asc).ravel()[0]) == 0,
        software_version=_text(a.get("N_Software_Version", b"")),
        algorithm_version=_text(a.get("N_Algorithm_Version", b"")),
        aux_files=_texts(a.get("N_Aux_Filename")), anc_files=_texts(a.get("N_Anc_Filename")))


def _clean(path, dataset: str, raw: np.ndarray, f) -> np.ndarray:
    if f.kind == "float":
        # Per-scan and per-FOV fields become float64; VIIRS pixel arrays and spectra stay float32 (memory).
        wide = raw.dtype == np.float64 or (raw.ndim < 4 and f.per != "row")
        out = raw.astype(np.float64 if wide else np.float32)
        out[is_float_fill(raw)] = np.nan
        return out * f.to_si if f.to_si != 1.0 else out
    if f.kind == "scaled":
        if raw.dtype.kind != "u":
            out = raw.astype(np.float32)
            out[is_float_fill(raw)] = np.nan
            return out
        out = raw.astype(np.float32)
        out[raw >= UINT16_FILL_MIN] = np.nan
        return out
    if f.kind == "time":
        return raw.astype(np.int64)
    return raw


def _product_granules(path: Path, h5: h5py.File, product: Product, platform: str, fields=None) -> list:
    group = product.data_group
    if group not in h5:
        raise GranuleError(path, group, "missing product group")
    n_gran_attr = None
    aggr = f"Data_Products/{product.collection}/{product.collection}_Aggr"
    if aggr in h5:
        n_gran_attr = h5[aggr].attrs.get("AggregateNumberGranules")
    n_gran = int(np.asarray(n_gran_attr).ravel()[0]) if n_gran_attr is not None else 1
    metas = [_granule_meta(path, h5, product, k, platform) for k in range(n_gran)]
    scans = [product.scans_reserved or m.n_scans for m in metas]
    bounds = np.concatenate([[0], np.cumsum(scans)])
    wanted = product.fields if fields is None else {k: product.fields[k] for k in fields}
    arrays = {}
    for key, f in wanted.items():
        name = f"{group}/{f.dataset}"
        if name not in h5:
            if f.required:
                raise GranuleError(path, name, "missing dataset")
            arrays[key] = None
            continue
        try:
            raw = h5[name][()]
        except (OSError, ValueError) as exc:
            raise GranuleError(path, name, f"unreadable ({exc})") from None
        per = product.rows_per_scan if f.per == "row" else 1
        if raw.ndim == 0 or raw.shape[0] != bounds[-1] * per:
            raise GranuleError(path, name, f"axis 0 has {raw.shape[0] if raw.ndim else 0} entries, "
                                           f"expected {bounds[-1] * per} for {n_gran} granule(s)")
        data = _clean(path, name, raw, f)
        if f.factors:
            fac_name = f"{group}/{f.factors}"
            if fac_name not in h5:
                raise GranuleError(path, fac_name, "missing scale factors")
            fac = np.asarray(h5[fac_name][()], np.float64).reshape(-1, 2)
            if len(fac) < n_gran:
                raise GranuleError(path, fac_name, f"{len(fac)} factor pairs for {n_gran} granules")
        parts = []
        for k in range(n_gran):
            part = data[bounds[k] * per:bounds[k + 1] * per]
            if f.factors:
                scale, offset = fac[k]
                if is_float_fill(scale) or is_float_fill(offset) or not np.isfinite(scale * offset):
                    raise GranuleError(path, fac_name, f"fill value in factors of granule {k}")
                part = (part * scale + offset).astype(np.float32)
            parts.append(part)
        arrays[key] = parts
    out = []
    for k, meta in enumerate(metas):
        kwargs = {key: (v[k] if v is not None else None) for key, v in arrays.items()}
        if product.kind == "cris_sdr":
            kwargs["wavenumber_cm1"] = cris_lw_wavenumbers_cm1(kwargs["radiance_lw"].shape[-1])
        if fields is not None:
            out.append((meta, kwargs))
            continue
        granule = _GRANULE_TYPES[product.kind](meta=meta, **kwargs)
        _check_not_all_fill(path, product, granule)
        out.append(granule)
    return out


_MAIN_FIELD = {"cris_geo": "lat_rad", "cris_sdr": "radiance_lw", "viirs_sdr": "bt_k", "viirs_geo": "lat_rad"}


def _check_not_all_fill(path, product: Product, granule) -> None:
    key = _MAIN_FIELD[product.kind]
    if not np.any(np.isfinite(getattr(granule, key))):
        raise GranuleError(path, f"{product.data_group}/{product.fields[key].dataset}",
                           f"granule {granule.meta.granule_id or '?'} holds only fill values")
    if product.kind == "viirs_geo" and "height_m" in product.fields:
        _check_height(path, f"{product.data_group}/{product.fields['height_m'].dataset}",
                      granule.lat_rad, granule.lon_rad, granule.height_m)


def _check_height(path, name, lat_rad, lon_rad, height_m) -> None:
    """A terrain-corrected pixel needs its height: fill only where the pixel itself is fill."""
    located = np.isfinite(lat_rad) & np.isfinite(lon_rad)
    missing = located & ~np.isfinite(height_m)
    if missing.any():
        r, c = np.argwhere(missing)[0]
        raise GranuleError(path, name, f"fill or non-finite at {int(missing.sum())} geolocated pixel(s), "
                                       f"first at row {r}, column {c}")
    bad = located & ((height_m < -500.0) | (height_m > 9000.0))
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise GranuleError(path, name, f"terrain height {float(height_m[r, c]):.6g} m at row {r}, column {c} "
                                       f"is outside -500..9000 m")


def _open(path: Path) -> h5py.File:
    try:
        return h5py.File(path, "r")
    except (OSError, ValueError) as exc:
        raise GranuleError(path, "(file)", f"not a readable HDF5 file ({exc})") from None


def _platform(path: Path, h5: h5py.File) -> str:
    attr = h5.attrs.get("Platform_Short_Name")
    if attr is not None:
        return _text(attr).lower().replace("npp", "npp")
    parsed = parse_name(path.name)
    if parsed is None:
        raise GranuleError(path, "Platform_Short_Name", "missing and the file name is not a JPSS name")
    return parsed.platform


def products_in(path: Path, h5: h5py.File) -> list[Product]:
    """Products present in an open file, from the file name or, failing that, the groups."""
    parsed = parse_name(path.name)
    if parsed is not None:
        unknown = [p for p in parsed.products if p not in PRODUCTS]
        known = [PRODUCTS[p] for p in parsed.products if p in PRODUCTS]
        if known:
            return known
        raise GranuleError(path, "(file name)", f"no supported product among {', '.join(unknown)}")
    found = [p for p in PRODUCTS.values() if p.data_group in h5]
    if not found:
        raise GranuleError(path, "All_Data", "no supported product group")
    return found


def read_file(path, kinds=None) -> list:
    """All granules of the supported products in *path* (optionally only those of *kinds*)."""
    path = Path(path)
    with _open(path) as h5:
        platform = _platform(path, h5)
        out = []
        for product in products_in(path, h5):
            if kinds is None or product.kind in kinds:
                out.extend(_product_granules(path, h5, product, platform))
        return out


def read_metadata(path) -> list[GranuleMeta]:
    """Granule metadata of every product in *path*, without reading the arrays."""
    path = Path(path)
    with _open(path) as h5:
        platform = _platform(path, h5)
        metas = []
        for product in products_in(path, h5):
            aggr = f"Data_Products/{product.collection}/{product.collection}_Aggr"
            n = 1
            if aggr in h5 and "AggregateNumberGranules" in h5[aggr].attrs:
                n = int(np.asarray(h5[aggr].attrs["AggregateNumberGranules"]).ravel()[0])
            metas.extend(_granule_meta(path, h5, product, k, platform) for k in range(n))
        return metas


def read_viirs_geo_scan(path, scan: int):
    """(lat_rad, lon_rad, height_m) of one 32-row scan of a VIIRS GEO file (negative *scan* counts from the
    end); height_m is zero for the ellipsoid product."""
    path = Path(path)
    with _open(path) as h5:
        product = next((p for p in products_in(path, h5) if p.kind == "viirs_geo"), None)
        if product is None:
            raise GranuleError(path, "All_Data", "no VIIRS geolocation product")
        out = []
        for key in ("lat_rad", "lon_rad", "height_m"):
            if key not in product.fields:
                out.append(np.zeros_like(out[0]))
                continue
            f = product.fields[key]
            name = f"{product.data_group}/{f.dataset}"
            if name not in h5:
                raise GranuleError(path, name, "missing dataset")
            rows = h5[name].shape[0]
            start = (scan % (rows // product.rows_per_scan)) * product.rows_per_scan
            out.append(_clean(path, name, h5[name][start:start + product.rows_per_scan], f))
        if "height_m" in product.fields:
            _check_height(path, f"{product.data_group}/Height", *out)
        return tuple(out)
