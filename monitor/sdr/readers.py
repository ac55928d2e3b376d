"""Read IDPS HDF5 files (single, aggregated or combined) into one typed object per granule.

A file may hold several products (``GCRSO-SCRIF_...``: one ``All_Data/<coll>_All`` group each) and
several granules concatenated on axis 0 (scans per granule from ``_Gran_k/N_Number_Of_Scans``; VIIRS
always reserves 48 scans). Every problem is raised as :class:`GranuleError` naming file and field.
"""

from __future__ import annotations

import datetime as dt
import os
from collections.abc import Collection, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from monitor.core.satellites import SATELLITES
from monitor.sdr import consistency
from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import (
    _GRANULE_TYPES,
    GranuleMeta,
    GranuleRef,
    as_ref,
)
from monitor.sdr.iet import iet_to_datetime
from monitor.sdr.names import parse_name
from monitor.sdr.products import (
    FLOAT_FILLS,
    IET_LIMITS_US,
    PRODUCTS,
    UINT16_FILL_MIN,
    Field,
    Product,
    cris_lw_wavenumbers_cm1,
    cris_sw_wavenumbers_cm1,
    is_float_fill,
)


def _text(value: object) -> str:
    a = np.asarray(value).ravel()
    v = a[0] if a.size else b""
    return v.decode("ascii", "replace").strip() if isinstance(v, bytes) else str(v)


def _texts(value: object) -> tuple[str, ...]:
    if value is None:
        return ()
    return tuple(
        v.decode("ascii", "replace").strip() if isinstance(v, bytes) else str(v)
        for v in np.asarray(value).ravel()
    )


def _when(date: str, time: str) -> dt.datetime:
    t = time.rstrip("Z")
    return dt.datetime.strptime(f"{date} {t}", "%Y%m%d %H%M%S.%f").replace(tzinfo=dt.timezone.utc)


def _number(path: GranuleRef, name: str, value: object) -> int:
    """One integer attribute value, or GranuleError naming it (non-numeric, empty)."""
    try:
        v = np.asarray(value).ravel()[0]
        if isinstance(v, bytes):
            v = v.decode("ascii")
        return int(v)
    except (IndexError, ValueError, TypeError, UnicodeDecodeError, OverflowError):
        raise GranuleError(path, name, f"not a number: {_text(value)[:40]!r}") from None


def _granule_meta(path: GranuleRef, h5: h5py.File, product: Product, k: int, platform: str) -> GranuleMeta:
    name = f"Data_Products/{product.collection}/{product.collection}_Gran_{k}"
    if name not in h5:
        raise GranuleError(path, name, "missing granule metadata")
    a = h5[name].attrs
    for key in ("N_Beginning_Time_IET", "N_Ending_Time_IET", "N_Number_Of_Scans"):
        if key not in a:
            raise GranuleError(path, f"{name}/{key}", "missing attribute")
    for key in ("N_Beginning_Time_IET", "N_Ending_Time_IET"):
        kind = np.asarray(a[key]).dtype.kind
        if kind in "fc":  # a float time has lost its microseconds (float64 holds 15.95 digits of 16)
            raise GranuleError(path, f"{name}/{key}", f"{_text(a[key])[:40]} is a float, not an integer time")
    start_iet = _number(path, f"{name}/N_Beginning_Time_IET", a["N_Beginning_Time_IET"])
    end_iet = _number(path, f"{name}/N_Ending_Time_IET", a["N_Ending_Time_IET"])
    n_scans = _number(path, f"{name}/N_Number_Of_Scans", a["N_Number_Of_Scans"])
    for key, value in (("N_Beginning_Time_IET", start_iet), ("N_Ending_Time_IET", end_iet)):
        if not IET_LIMITS_US[0] <= value <= IET_LIMITS_US[1]:
            raise GranuleError(path, f"{name}/{key}", f"{value} is not an IET time of the JPSS era")
    if not 0 <= end_iet - start_iet <= 600_000_000:
        raise GranuleError(
            path,
            f"{name}/N_Ending_Time_IET",
            f"{end_iet} is not within 10 min after the beginning {start_iet}",
        )
    limit = product.scans_reserved or 64
    if not 1 <= n_scans <= limit:
        raise GranuleError(path, f"{name}/N_Number_Of_Scans", f"{n_scans} is not within 1..{limit}")
    try:
        text_times = (
            _when(_text(a["Beginning_Date"]), _text(a["Beginning_Time"])),
            _when(_text(a["Ending_Date"]), _text(a["Ending_Time"])),
        )
    except (KeyError, ValueError):  # the IET times are the granule's; the text is a copy of them
        text_times = None
    start, end = text_times or (iet_to_datetime(start_iet), iet_to_datetime(end_iet))
    asc = a.get("Ascending/Descending_Indicator")
    orbit = a.get("N_Beginning_Orbit_Number")
    granule_id = _text(a.get("N_Granule_ID", b""))
    if granule_id and not granule_id.upper().startswith(platform.upper()):
        raise GranuleError(path, f"{name}/N_Granule_ID", f"{granule_id!r} is not a granule of {platform}")
    meta = GranuleMeta(
        path=str(path),
        product=product.prefix,
        collection=product.collection,
        platform=platform,
        granule_id=granule_id,
        orbit=0 if orbit is None else _number(path, f"{name}/N_Beginning_Orbit_Number", orbit),
        start=start,
        end=end,
        start_iet_us=start_iet,
        end_iet_us=end_iet,
        n_scans=n_scans,
        ascending=None if asc is None else _number(path, f"{name}/Ascending/Descending_Indicator", asc) == 0,
        software_version=_text(a.get("N_Software_Version", b"")),
        algorithm_version=_text(a.get("N_Algorithm_Version", b"")),
        aux_files=_texts(a.get("N_Aux_Filename")),
        anc_files=_texts(a.get("N_Anc_Filename")),
    )
    parsed = parse_name(path.name)
    consistency.check_identity(path, name, meta, text_times, parsed.orbit if parsed and k == 0 else None)
    if product.kind in ("cris_geo", "cris_sdr"):
        consistency.check_cris_span(path, name, meta)
    return meta


def _check_raw(path: GranuleRef, name: str, raw: np.ndarray | h5py.Dataset, f: Field, rows: int) -> None:
    """Dtype family and full shape of a dataset (an array, or an HDF5 dataset not yet read) against the
    product table."""
    # a scaled field is stored as counts (uint16): a float there would be scaled as counts, silently wrong
    kinds = {"float": "f", "scaled": "u", "time": "i", "flags": "u"}[f.kind]
    if (
        raw.dtype.kind not in kinds
        or raw.dtype.itemsize < {"f": 4, "u": 2 if f.kind == "scaled" else 1, "i": 1}[raw.dtype.kind]
    ):
        raise GranuleError(path, name, f"dtype {raw.dtype} is not a {f.kind} dataset")
    expected = (rows,) + tuple(f.dims)
    if raw.shape != expected:
        raise GranuleError(path, name, f"shape {raw.shape}, expected {expected}")


def _check_values(path: GranuleRef, name: str, data: np.ndarray, f: Field) -> None:
    """Physical limits of every value that is not a fill (file units, after scaling)."""
    if f.limits is not None:
        if data.dtype.kind == "f":  # fmin/fmax skip NaN (fill) without a copy; all NaN gives NaN
            lo, hi = np.fmin.reduce(data, axis=None), np.fmax.reduce(data, axis=None)
        else:
            v = data[data > 0] if f.kind == "time" else data
            lo, hi = (v.min(), v.max()) if v.size else (np.nan, np.nan)
        if not np.isnan(lo):
            if lo < f.limits[0] or hi > f.limits[1]:
                bad = lo if lo < f.limits[0] else hi
                raise GranuleError(path, name, f"value {bad:.6g} outside {f.limits[0]:g}..{f.limits[1]:g}")
    if f.norm is not None:
        n = np.linalg.norm(data, axis=-1)
        n = n[np.isfinite(n)]
        if n.size and (n.min() < f.norm[0] or n.max() > f.norm[1]):
            bad = n.min() if n.min() < f.norm[0] else n.max()
            raise GranuleError(path, name, f"vector length {bad:.6g} outside {f.norm[0]:g}..{f.norm[1]:g}")


def _clean(raw: np.ndarray, f: Field) -> np.ndarray:
    if f.kind == "float":
        # Per-scan and per-FOV fields become float64; VIIRS pixel arrays and spectra stay float32 (memory).
        wide = raw.dtype == np.float64 or (raw.ndim < 4 and f.per != "row")
        out = raw.astype(np.float64 if wide else np.float32, copy=False)
        out[is_float_fill(raw)] = np.nan
        return out
    if f.kind == "scaled":
        out = raw.astype(np.float32)
        out[is_float_fill(raw) if raw.dtype.kind == "f" else raw >= UINT16_FILL_MIN] = np.nan
        return out
    if f.kind == "time":
        return raw.astype(np.int64)
    return raw


def _factors(path: GranuleRef, h5: h5py.File, group: str, f: Field, n_gran: int) -> np.ndarray:
    """(scale, offset) per granule: present, finite, scale > 0."""
    name = f"{group}/{f.factors}"
    if name not in h5:
        raise GranuleError(path, name, "missing scale factors")
    raw = np.asarray(h5[name][()])
    if raw.dtype.kind not in "fiu" or raw.size < 2 * n_gran:
        raise GranuleError(path, name, f"{raw.size} {raw.dtype} values for {n_gran} granule(s)")
    fac = raw.astype(np.float64).ravel()[: 2 * n_gran].reshape(-1, 2)
    for k, (scale, offset) in enumerate(fac):
        if is_float_fill(scale) or is_float_fill(offset):
            raise GranuleError(path, name, f"fill value in factors of granule {k}")
        if not (np.isfinite(scale) and np.isfinite(offset) and 0 < scale < 1e3 and abs(offset) < 1e6):
            raise GranuleError(
                path, name, f"scale {scale:g}, offset {offset:g} of granule {k} are not usable"
            )
    return fac


def _fill_of(f: Field, dtype: np.dtype) -> float | int:
    """The value standing for "not read" in a per-row array: a fill the field's cleaning turns to NaN
    (floats, scaled counts) or the largest flag (never the good value 0)."""
    if dtype.kind == "f":
        return FLOAT_FILLS[0]
    return UINT16_FILL_MIN if f.kind == "scaled" else np.iinfo(dtype).max


def _read_array(
    path: GranuleRef, h5: h5py.File, name: str, f: Field, rows: int, kept: slice | None
) -> np.ndarray:
    """A dataset checked against the product table (dtype, shape) before any of its data is read; with
    *kept* (a row slice), only those rows are read and the others hold a fill value."""
    try:
        ds = h5[name]
        _check_raw(path, name, ds, f, rows)
        if kept is None:
            raw = ds[()]
        else:
            raw = np.full(ds.shape, _fill_of(f, ds.dtype), ds.dtype)
            raw[kept] = ds[kept]
    except GranuleError:
        raise
    except (OSError, ValueError, TypeError, RuntimeError, KeyError, AttributeError) as exc:
        raise GranuleError(path, name, f"unreadable ({exc})") from None
    if not isinstance(raw, np.ndarray) or raw.ndim == 0:
        raise GranuleError(path, name, "not an array")
    return raw


def _product_granules(
    path: GranuleRef, h5: h5py.File, product: Product, platform: str, scans: slice | None = None
) -> list:
    group = product.data_group
    if group not in h5:
        raise GranuleError(path, group, "missing product group")
    n_gran_attr = None
    aggr = f"Data_Products/{product.collection}/{product.collection}_Aggr"
    if aggr in h5:
        n_gran_attr = h5[aggr].attrs.get("AggregateNumberGranules")
    n_gran = 1 if n_gran_attr is None else _number(path, f"{aggr}/AggregateNumberGranules", n_gran_attr)
    if not 1 <= n_gran <= 1000:
        raise GranuleError(path, f"{aggr}/AggregateNumberGranules", f"{n_gran} is not within 1..1000")
    metas = [_granule_meta(path, h5, product, k, platform) for k in range(n_gran)]
    bounds = np.concatenate([[0], np.cumsum([product.scans_reserved or m.n_scans for m in metas])])
    kept = None  # the rows of *scans*, for a single-granule product of fixed scans (VIIRS)
    if scans is not None and product.scans_reserved and n_gran == 1 and scans != slice(None):
        first, stop, _ = scans.indices(product.scans_reserved)
        kept = slice(first * product.rows_per_scan, stop * product.rows_per_scan)
    arrays: dict[str, list[np.ndarray] | None] = {}
    for key, f in product.fields.items():
        name = f"{group}/{f.dataset}"
        if name not in h5:
            if f.required:
                raise GranuleError(path, name, "missing dataset")
            arrays[key] = None
            continue
        per = product.rows_per_scan if f.per == "row" else 1
        raw = _read_array(path, h5, name, f, int(bounds[-1] * per), kept if f.per == "row" else None)
        if f.kind == "scaled" and raw.dtype.kind == "u":
            consistency.check_raw_counts(path, name, raw)
        data = _clean(raw, f)
        fac = _factors(path, h5, group, f, n_gran) if f.factors else None
        parts = []
        for k in range(n_gran):
            part = data[bounds[k] * per : bounds[k + 1] * per]
            if fac is not None:
                part = (part * fac[k, 0] + fac[k, 1]).astype(np.float32)
            _check_values(path, name, part, f)
            if f.to_si != 1.0:
                part *= f.to_si  # part is this reader's own array (a copy or a slice of one)
            parts.append(part)
        arrays[key] = parts
    out = []
    for k, meta in enumerate(metas):
        # the product table names the fields: each granule type takes its own as keywords
        kwargs: dict[str, Any] = {key: (v[k] if v is not None else None) for key, v in arrays.items()}
        radiance = kwargs.get("radiance_lw")
        if product.kind == "cris_sdr" and radiance is not None:  # a required field: never None here
            kwargs["wavenumber_cm1"] = cris_lw_wavenumbers_cm1(radiance.shape[-1])
            if kwargs.get("radiance_sw") is not None:
                kwargs["wavenumber_sw_cm1"] = cris_sw_wavenumbers_cm1(kwargs["radiance_sw"].shape[-1])
        granule = _GRANULE_TYPES[product.kind](meta=meta, **kwargs)
        consistency.check_not_all_fill(path, product, granule)
        consistency.check_for_times(path, product, granule)
        consistency.check_relations(path, product, granule)
        out.append(granule)
    return out


def _failed(path: GranuleRef, fh: object) -> GranuleError | None:
    """The error for a read in place whose transport failed (its reason names the key), else None."""
    why = getattr(fh, "failure", None)
    return GranuleError(path, "(range read)", why) if why else None


@contextmanager
def _opened(path: GranuleRef) -> Iterator[h5py.File]:
    """The open HDF5 file of *path*; every error h5py raises on a corrupt structure, and every failed read
    in place, becomes a GranuleError naming the file (or key)."""
    fh = None if isinstance(path, Path) else path.open()
    try:
        try:
            h5 = h5py.File(path if fh is None else fh, "r")
        except (OSError, ValueError) as exc:
            raise _failed(path, fh) or GranuleError(
                path, "(file)", f"not a readable HDF5 file ({exc})"
            ) from None
        with h5, _reading(path, fh):
            yield h5
    finally:
        if fh is not None:
            fh.close()


@contextmanager
def _reading(path: GranuleRef, fh: object = None) -> Iterator[None]:
    """Errors h5py raises on corrupt metadata once a file is open become a GranuleError naming the file."""
    try:
        yield
    except GranuleError as exc:
        raise _failed(path, fh) or exc from None
    except (
        OSError,
        RuntimeError,
        KeyError,
        ValueError,
        TypeError,
        IndexError,
        OverflowError,
        UnicodeDecodeError,
    ) as exc:
        raise _failed(path, fh) or GranuleError(
            path, "(file)", f"corrupt or unreadable HDF5 structure ({type(exc).__name__}: {exc})"[:300]
        ) from None


def _platform(path: GranuleRef, h5: h5py.File) -> str:
    """The platform (npp, j01, j02) of the content; it must agree with the file name's."""
    parsed = parse_name(path.name)
    attr = h5.attrs.get("Platform_Short_Name")
    if attr is None:
        if parsed is None:
            raise GranuleError(path, "Platform_Short_Name", "missing and the file name is not a JPSS name")
        return parsed.platform
    platform = _text(attr).lower()
    if parsed is not None and parsed.platform != platform:
        raise GranuleError(
            path, "Platform_Short_Name", f"{_text(attr)!r} in a file named for {parsed.platform}"
        )
    if platform not in SATELLITES:
        raise GranuleError(
            path,
            "Platform_Short_Name",
            f"{_text(attr)!r} is not one of {', '.join(s.idps for s in SATELLITES.values())}",
        )
    return platform


def _check_name_time(path: GranuleRef, metas: Sequence[GranuleMeta]) -> None:
    """The file name's start time is its first granule's (to the tenth of a second; 60 s allowed)."""
    parsed = parse_name(path.name)
    if parsed is None or not metas:
        return
    first = min(m.start for m in metas)
    if abs((first - parsed.start).total_seconds()) > 60:
        raise GranuleError(
            path,
            "(file name)",
            f"start {parsed.start:%Y-%m-%d %H:%M:%S} but the first granule begins {first:%Y-%m-%d %H:%M:%S}",
        )


def products_in(path: GranuleRef, h5: h5py.File) -> list[Product]:
    """Products present in an open file, from the file name or, failing that, the groups.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    h5 : h5py.File
        It, open.

    Returns
    -------
    list of Product
        The supported products it holds.
    """
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


def read_file(
    path: str | os.PathLike[str] | GranuleRef,
    kinds: Collection[str] | None = None,
    scans: slice | None = None,
) -> list:  # of Granule: the caller knows which *kinds* it asked for
    """All granules of the supported products in *path* (optionally only those of *kinds*), every field
    checked against the product table; any problem is a :class:`GranuleError` naming file and field.

    *scans* (VIIRS, one granule per file) reads only the pixel rows of those scans; the other rows hold
    fill, as scans without data do (only the bytes of the scans a CrIS granule can reach travel).

    Parameters
    ----------
    path : str or os.PathLike or GranuleRef
        The file.
    kinds : collection of str, optional
        Only granules of these kinds.
    scans : slice, optional
        Only these scans (the others hold fill).

    Returns
    -------
    list of Granule
        The granules.
    """
    path = as_ref(path)
    with _opened(path) as h5:
        platform = _platform(path, h5)
        out = []
        for product in products_in(path, h5):
            if kinds is None or product.kind in kinds:
                out.extend(_product_granules(path, h5, product, platform, scans))
        _check_name_time(path, [g.meta for g in out])
        return out


def read_metadata(path: str | os.PathLike[str] | GranuleRef) -> list[GranuleMeta]:
    """Granule metadata of every product in *path*, without reading the arrays.

    Parameters
    ----------
    path : str or os.PathLike or GranuleRef
        The file.

    Returns
    -------
    list of GranuleMeta
        Per granule.
    """
    path = as_ref(path)
    with _opened(path) as h5:
        platform = _platform(path, h5)
        metas: list[GranuleMeta] = []
        for product in products_in(path, h5):
            aggr = f"Data_Products/{product.collection}/{product.collection}_Aggr"
            n = 1
            if aggr in h5 and "AggregateNumberGranules" in h5[aggr].attrs:
                n = _number(
                    path, f"{aggr}/AggregateNumberGranules", h5[aggr].attrs["AggregateNumberGranules"]
                )
                if not 1 <= n <= 1000:
                    raise GranuleError(path, f"{aggr}/AggregateNumberGranules", f"{n} is not within 1..1000")
            metas.extend(_granule_meta(path, h5, product, k, platform) for k in range(n))
        _check_name_time(path, metas)
        return metas


def read_viirs_geo_scan(path: str | os.PathLike[str] | GranuleRef, scan: int) -> tuple[np.ndarray, ...]:
    """(lat_rad, lon_rad, height_m) of one scan (32 rows on the I grid, 16 on the M) of a VIIRS GEO file
    (negative *scan* counts from the end); height_m is zero for the ellipsoid product.

    Parameters
    ----------
    path : str or os.PathLike or GranuleRef
        A VIIRS GEO file.
    scan : int
        The scan (negative from the end).

    Returns
    -------
    tuple of numpy.ndarray
        (lat_rad, lon_rad, height_m) of its rows.
    """
    path = as_ref(path)
    with _opened(path) as h5:
        product = next((p for p in products_in(path, h5) if p.kind == "viirs_geo"), None)
        if product is None:
            raise GranuleError(path, "All_Data", "no VIIRS geolocation product")
        out: list[np.ndarray] = []
        for key in ("lat_rad", "lon_rad", "height_m"):
            if key not in product.fields:
                out.append(np.zeros_like(out[0]))
                continue
            f = product.fields[key]
            name = f"{product.data_group}/{f.dataset}"
            if name not in h5:
                raise GranuleError(path, name, "missing dataset")
            rows = h5[name].shape[0]
            if rows < product.rows_per_scan:
                raise GranuleError(path, name, f"{rows} rows, less than one scan")
            start = (scan % (rows // product.rows_per_scan)) * product.rows_per_scan
            raw = h5[name][start : start + product.rows_per_scan]
            _check_raw(path, name, raw, f, product.rows_per_scan)
            data = _clean(raw, f)
            _check_values(path, name, data, f)
            out.append(data * f.to_si if f.to_si != 1.0 else data)
        if "height_m" in product.fields:
            consistency.check_height(path, f"{product.data_group}/Height", *out)
        return tuple(out)


def read_scan_start_us(path: str | os.PathLike[str] | GranuleRef) -> np.ndarray:
    """The start time (IET us) of every scan of a VIIRS GEO file, read alone (a few hundred bytes):
    enough to choose the scans a CrIS granule can reach before any pixel is read.

    Parameters
    ----------
    path : str or os.PathLike or GranuleRef
        A VIIRS GEO file.

    Returns
    -------
    numpy.ndarray
        Each scan's StartTime, IET us.
    """
    path = as_ref(path)
    with _opened(path) as h5:
        product = next((p for p in products_in(path, h5) if p.kind == "viirs_geo"), None)
        if product is None:
            raise GranuleError(path, "All_Data", "no VIIRS geolocation product")
        f = product.fields["start_time_us"]
        name = f"{product.data_group}/{f.dataset}"
        if name not in h5:
            raise GranuleError(path, name, "missing dataset")
        return np.asarray(h5[name][()], np.int64).ravel()
