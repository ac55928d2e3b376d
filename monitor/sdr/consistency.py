"""What a genuine IDPS granule obeys beyond the types, shapes and ranges of its product table.

A file can pass every per-field check and still be wrong: a constant Latitude, a MidTime a day late, an
attitude a thousand times too large, another granule's ID, an S-NPP granule under a NOAA-20 name. These
checks tie fields together by the physics and bookkeeping of the instruments; each failure is a
:class:`GranuleError` naming the file, the field and the relation it breaks. Margins, measured on the ten
real NOAA-20 GCRSO granules of tests/data/real and on the simulator (docs/jpss-formats.md):

* **Identity.** The granule ID is the platform and the tenths of a second since the IDPS granule epoch
  (IET 1.698019238e15 us), so ``N_Beginning_Time_IET - ID x 1e5 us`` is that epoch to within a granule
  (real: the same to 1 us; allowed 10 s, a CrIS granule is 32 s). The orbit number (file name and
  attribute) counts orbits since the satellite's launch
  (:meth:`monitor.core.satellites.Satellite.orbit_number`;
  real: 4790 for 4790.0, allowed 0.5 % + 20); S-NPP and NOAA-20 differ by ~31 000 orbits. The text dates
  agree with the IET times (1 s).
* **Scans.** CrIS scans are 8 s apart and a granule spans ``(n-1) x 8 < span <= n x 8`` s (real: 29.8 s for
  4 scans). VIIRS arrays always hold 48 scans: those past ``N_Number_Of_Scans`` are fill, the counted
  ones are not all fill.
* **Scan times.** StartTime and MidTime exist for every scan that holds data, increase in whole scan
  periods (within 2 %), MidTime follows StartTime by less than a period, and all lie within the granule.
* **Ephemeris.** ``|SCPosition|`` is the satellite's orbit radius within 30 km (real: 1.2 km off) and
  ``|SCVelocity|`` (ECEF) 7.3 .. 7.7 km/s (real: 7.53).
* **Attitude.** Roll, pitch and yaw within 300 arcsec (real: < 2), consecutive scans within 30 arcsec
  (real: < 1.3), and not exactly zero everywhere (a measured attitude never is).
* **Line of sight (CrIS GEO).** The FOV's ground point (lat, lon, h = 0) plus SatelliteRange along the
  zenith/azimuth direction is the spacecraft at the FOR time (Wang et al. 2017, section 2.2 steps 1-2;
  real: within 2.0 m, allowed 200 m).
* **Nadir (VIIRS GEO).** The middle pixel of each scan lies below the spacecraft: its distance equals the
  spacecraft's height above it within 20 km (simulator: 0.1 km; a wrong position, time or pixel is
  hundreds of km off).
* **VIIRS BT.** At most 0.5 % of the pixels at raw count 0 (the scaled minimum, 150 K and below: no scene
  piles up there), and no other raw count holding more than 1 % of the pixels (the noise alone, 0.4 K,
  spreads a uniform scene over ~250 counts of 0.003 K; a value stamped over the array piles up).
* **CrIS spectra.** No FOV's long-wave spectrum exactly zero in every channel (no scene radiates nothing).
* **Fill.** A granule's main field is not all fill; Latitude and Longitude are fill together; a
  terrain-corrected pixel has its height, -500..9000 m.
* **CrIS FOR times.** They increase and lie within the granule (10 s of margin: the bounds are nominal).

The readers (:mod:`monitor.sdr.readers`) call :func:`check_not_all_fill`, :func:`check_for_times` and
:func:`check_relations` on every granule they give.
"""

from __future__ import annotations

import datetime as dt

import numpy as np

from monitor.core.constants import CRIS_SCAN_US, VIIRS_SCAN_US
from monitor.core.satellites import SATELLITES
from monitor.sdr.geolocation import check_ephemeris, check_line_of_sight, check_nadir, check_pixel_steps
from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import (
    CrisGeoGranule,
    CrisSdrGranule,
    GeoGranule,
    Granule,
    GranuleMeta,
    GranuleRef,
    ViirsGeoGranule,
    ViirsSdrGranule,
)
from monitor.sdr.iet import iet_to_datetime
from monitor.sdr.products import UINT16_FILL_MIN, Product

GRANULE_ID_EPOCH_IET_US = 1_698_019_238_000_000  # docs/jpss-formats.md 1.2
SCAN_US = {
    "cris_geo": CRIS_SCAN_US,
    "cris_sdr": CRIS_SCAN_US,
    "viirs_geo": VIIRS_SCAN_US,
    "viirs_sdr": VIIRS_SCAN_US,
}
ID_TOLERANCE_US = 10_000_000
TEXT_TIME_TOLERANCE_S = 1.0
ORBIT_TOLERANCE = (0.005, 20)  # relative, absolute
RAW_ZERO_SHARE = 0.005
RAW_ONE_COUNT_SHARE = 0.01


def granule_id_time_us(granule_id: str) -> int | None:
    """The IET (us) a granule ID stands for, or None if it is not ``<3 letters><12 digits>``.

    Parameters
    ----------
    granule_id : str
        ``<3 letters><12 digits>``.

    Returns
    -------
    int or None
        The IET, us; None for another form.
    """
    digits = granule_id[3:]
    if len(granule_id) != 15 or not digits.isascii() or not digits.isdigit():
        return None
    return GRANULE_ID_EPOCH_IET_US + int(digits) * 100_000


def check_identity(
    path: GranuleRef,
    name: str,
    meta: GranuleMeta,
    text_times: tuple[dt.datetime, dt.datetime] | None,
    file_orbit: int | None,
) -> None:
    """Granule ID, orbit number, text dates and scan count against the IET times (*name* is the
    ``_Gran_k`` group; *text_times* the (start, end) parsed from the text attributes, or None).

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    name : str
        The ``_Gran_k`` group.
    meta : GranuleMeta
        The granule's metadata.
    text_times : tuple of datetime, optional
        (start, end) parsed from the text attributes.
    file_orbit : int, optional
        The orbit the file's name gives.
    """
    sat = SATELLITES[meta.platform]
    if not meta.granule_id:
        raise GranuleError(path, f"{name}/N_Granule_ID", "missing: a granule without an ID cannot be paired")
    id_us = granule_id_time_us(meta.granule_id)
    if id_us is None:
        raise GranuleError(path, f"{name}/N_Granule_ID", f"{meta.granule_id!r} is not PLATFORM + 12 digits")
    if abs(meta.start_iet_us - id_us) > ID_TOLERANCE_US:
        raise GranuleError(
            path,
            f"{name}/N_Granule_ID",
            f"{meta.granule_id} stands for IET {id_us}, the granule begins at {meta.start_iet_us} "
            f"({(meta.start_iet_us - id_us) / 1e6:+.0f} s): another granule's ID",
        )
    expected = sat.orbit_number(meta.start.timestamp())
    allowed = ORBIT_TOLERANCE[0] * expected + ORBIT_TOLERANCE[1]
    for field, value in ((f"{name}/N_Beginning_Orbit_Number", meta.orbit), ("(file name)", file_orbit)):
        if value is not None and abs(value - expected) > allowed:
            raise GranuleError(
                path,
                field,
                f"orbit {value}, but {sat.name} flies orbit ~{expected} on {meta.start:%Y-%m-%d} "
                f"(orbits since its launch): not a granule of {sat.name}",
            )
    if text_times is not None:
        for which, text, iet_us in (
            ("Beginning", text_times[0], meta.start_iet_us),
            ("Ending", text_times[1], meta.end_iet_us),
        ):
            if abs((text - iet_to_datetime(iet_us)).total_seconds()) > TEXT_TIME_TOLERANCE_S:
                raise GranuleError(
                    path,
                    f"{name}/{which}_Time",
                    f"{text:%Y-%m-%d %H:%M:%S.%f} differs from N_{which}_Time_IET {iet_us} "
                    f"({iet_to_datetime(iet_us):%Y-%m-%d %H:%M:%S.%f})",
                )


def check_cris_span(path: GranuleRef, name: str, meta: GranuleMeta) -> None:
    """A CrIS granule of n scans spans more than n - 1 and at most n scan periods.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    name : str
        The ``_Gran_k`` group.
    meta : GranuleMeta
        The granule's metadata.
    """
    span = meta.end_iet_us - meta.start_iet_us
    if not (meta.n_scans - 1) * CRIS_SCAN_US < span <= meta.n_scans * CRIS_SCAN_US:
        raise GranuleError(
            path,
            f"{name}/N_Number_Of_Scans",
            f"{meta.n_scans} scans of 8 s, but the granule spans {span / 1e6:.1f} s",
        )


def _scans_with_data(granule: Granule, key: str, rows_per_scan: int) -> np.ndarray:
    data = getattr(granule, key)
    finite = np.isfinite(data).reshape(data.shape[0] // rows_per_scan, -1)
    return finite.any(axis=1)


def check_viirs_scan_count(path: GranuleRef, product: Product, granule: Granule, key: str) -> None:
    """VIIRS arrays hold 48 scans: those past N_Number_Of_Scans are fill, the last counted one is not.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    key : str
        The dataset checked.
    """
    has = _scans_with_data(granule, key, product.rows_per_scan)
    n = granule.meta.n_scans
    name = f"{product.data_group}/{product.fields[key].dataset}"
    if has[n:].any():
        first = n + int(np.argmax(has[n:]))
        raise GranuleError(path, name, f"scan {first + 1} holds data, but N_Number_Of_Scans is {n}")


def check_scan_times(path: GranuleRef, product: Product, granule: GeoGranule, has_data: np.ndarray) -> None:
    """StartTime and MidTime of every scan with data: present, increasing by whole scan periods, MidTime
    within a period after StartTime, inside the granule.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    has_data : numpy.ndarray
        Per scan, whether it holds data.
    """
    period = SCAN_US[product.kind]
    meta = granule.meta
    lo, hi = meta.start_iet_us - 10_000_000, meta.end_iet_us + 10_000_000
    start, mid = granule.start_time_us[has_data], granule.mid_time_us[has_data]
    for field, t in (("StartTime", start), ("MidTime", mid)):
        name = f"{product.data_group}/{field}"
        if (t <= 0).any():
            i = int(np.flatnonzero(has_data)[np.argmax(t <= 0)])
            raise GranuleError(path, name, f"scan {i + 1} holds data but its time is {int(t[t <= 0][0])}")
        if t.min() < lo or t.max() > hi:
            bad = int(t.min() if t.min() < lo else t.max())
            raise GranuleError(
                path, name, f"time {bad} (IET us) outside the granule {meta.start_iet_us}..{meta.end_iet_us}"
            )
        steps = np.diff(t) / period
        off = np.abs(steps - np.round(steps)) > 0.02
        if ((steps < 0.98) | off).any():
            i = int(np.argmax((steps < 0.98) | off))
            raise GranuleError(
                path,
                name,
                f"scans {i + 1} and {i + 2} are {np.diff(t)[i] / 1e6:.4f} s apart, not a multiple of "
                f"the {period / 1e6:g} s scan period",
            )
    lag = mid - start
    if ((lag <= 0) | (lag >= period)).any():
        i = int(np.argmax((lag <= 0) | (lag >= period)))
        raise GranuleError(
            path,
            f"{product.data_group}/MidTime",
            f"MidTime - StartTime is {lag[i] / 1e6:.3f} s in a scan, not within 0..{period / 1e6:g} s",
        )


def check_raw_counts(path: GranuleRef, name: str, raw: np.ndarray) -> None:
    """Scaled VIIRS BT (uint16): raw count 0 is the scaled minimum, which no scene fills, and no real scene
    piles up on one count.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    name : str
        The dataset.
    raw : numpy.ndarray
        Its raw counts.
    """
    counts = np.bincount(raw.ravel(), minlength=UINT16_FILL_MIN)[:UINT16_FILL_MIN]  # fills left out
    valid = int(counts.sum())
    if counts[0] > RAW_ZERO_SHARE * raw.size:
        raise GranuleError(
            path,
            name,
            f"{counts[0]} values ({100 * counts[0] / raw.size:.1f} %) at raw count 0, the scale's bottom",
        )
    top = int(np.argmax(counts))
    if valid and counts[top] > RAW_ONE_COUNT_SHARE * valid:
        raise GranuleError(
            path,
            name,
            f"{counts[top]} values ({100 * counts[top] / valid:.1f} % of the valid ones) at one raw "
            f"count, {top}: stamped, not measured",
        )


def check_spectra(path: GranuleRef, name: str, radiance: np.ndarray) -> None:
    """CrIS: no FOV spectrum exactly zero in every channel; the spectra mostly positive (a sign lost turns
    them negative); and not one spectrum copied to every FOV (measured FOVs always differ).

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    name : str
        The dataset.
    radiance : numpy.ndarray
        The spectra, channels last.
    """
    dead = np.all(radiance == 0, axis=-1)
    if dead.any():
        raise GranuleError(
            path, name, f"the spectra of {int(dead.sum())} FOV(s) are exactly zero in every channel"
        )
    spectra = radiance.reshape(-1, radiance.shape[-1])
    spectra = spectra[np.isfinite(spectra).all(axis=-1)]
    if spectra.shape[0] < 2:
        return
    if np.median(spectra) < 0:
        raise GranuleError(path, name, f"median radiance {np.median(spectra):.3g}: the spectra are negative")
    if np.all(spectra == spectra[0]):
        raise GranuleError(path, name, f"every one of {spectra.shape[0]} FOVs holds the same spectrum")


# A real scene (and the simulator's) changes little from one pixel to the next along a row against its
# spread over the granule; shuffled pixels or noise change as much as the whole spread.
STRUCTURE_RATIO = 0.5


def check_structure(path: GranuleRef, name: str, bt_k: np.ndarray) -> None:
    """VIIRS: neighbouring pixels along a row resemble each other, as a scene's do: the median step between
    neighbours is a small part of the interquartile range of the granule's values.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    name : str
        The dataset.
    bt_k : numpy.ndarray
        The band's BT, K, rows x columns.
    """
    step = np.abs(np.diff(bt_k[::8], axis=1))  # every eighth row: enough, and cheap
    step = step[np.isfinite(step)]
    values = bt_k[::8][np.isfinite(bt_k[::8])]
    if step.size < 1000 or values.size < 1000:
        return
    q25, q75 = np.percentile(values, [25, 75])
    spread = q75 - q25
    if spread > 0 and np.median(step) > STRUCTURE_RATIO * spread:
        raise GranuleError(
            path,
            name,
            f"neighbouring pixels differ by {np.median(step):.2f} K (median) against a spread of "
            f"{spread:.2f} K: no scene looks like that (shuffled or noise)",
        )


def check_relations(path: GranuleRef, product: Product, granule: Granule) -> None:
    """The relations between fields a genuine granule obeys (:mod:`monitor.sdr.consistency`).

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    """
    key = MAIN_FIELD[product.kind]
    if isinstance(granule, CrisSdrGranule):
        check_spectra(path, f"{product.data_group}/{product.fields[key].dataset}", granule.radiance_lw)
        if granule.radiance_sw is not None:
            sw = product.fields["radiance_sw"].dataset
            check_spectra(path, f"{product.data_group}/{sw}", granule.radiance_sw)
    if product.scans_reserved:
        check_viirs_scan_count(path, product, granule, key)
    if isinstance(granule, ViirsSdrGranule):
        check_structure(path, f"{product.data_group}/{product.fields[key].dataset}", granule.bt_k)
    if not isinstance(granule, (CrisGeoGranule, ViirsGeoGranule)):
        return
    has_data = np.isfinite(granule.lat_rad).reshape(len(granule.start_time_us), -1).any(axis=1)  # per scan
    check_scan_times(path, product, granule, has_data)
    check_ephemeris(path, product, granule, has_data)
    if isinstance(granule, CrisGeoGranule):
        check_line_of_sight(path, product, granule)
    else:
        check_nadir(path, product, granule, has_data)
        check_pixel_steps(path, product, granule)


def check_for_times(path: GranuleRef, product: Product, granule: Granule) -> None:
    """CrIS FOR times increase and lie within the granule (10 s of margin: the IDPS granule bounds are
    nominal); the per-scan times of both GEO products are checked with the physics
    (:func:`monitor.sdr.check_scan_times`).

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    """
    t = getattr(granule, "for_time_us", None)
    name = f"{product.data_group}/FORTime"
    if t is None:  # VIIRS GEO: per-scan times only; SDR files: their times are their GEO's
        return
    if isinstance(granule, CrisGeoGranule):
        # a FOR that has positions has a time: without one its FOVs would be dropped without a word
        placed = np.isfinite(granule.lat_rad).any(axis=-1)
        untimed = placed & (t <= 0)
        if untimed.any():
            raise GranuleError(
                path, name, f"{int(untimed.sum())} FOR(s) geolocated without a time (values {t[untimed][:3]})"
            )
    t = t.ravel()
    t = t[t > 0]
    lo, hi = granule.meta.start_iet_us - 10_000_000, granule.meta.end_iet_us + 10_000_000
    if t.size and (t.min() < lo or t.max() > hi):
        bad = t.min() if t.min() < lo else t.max()
        raise GranuleError(
            path,
            name,
            f"time {bad} (IET us) outside the granule {granule.meta.start_iet_us}..{granule.meta.end_iet_us}",
        )
    if np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise GranuleError(path, name, f"times do not increase: {t[i]} then {t[i + 1]}")


MAIN_FIELD = {"cris_geo": "lat_rad", "cris_sdr": "radiance_lw", "viirs_sdr": "bt_k", "viirs_geo": "lat_rad"}


def check_not_all_fill(path: GranuleRef, product: Product, granule: Granule) -> None:
    key = MAIN_FIELD[product.kind]
    if not np.any(np.isfinite(getattr(granule, key))):
        raise GranuleError(
            path,
            f"{product.data_group}/{product.fields[key].dataset}",
            f"granule {granule.meta.granule_id or '?'} holds only fill values",
        )
    if isinstance(granule, (ViirsGeoGranule, CrisGeoGranule)):
        lat_ok, lon_ok = np.isfinite(granule.lat_rad), np.isfinite(granule.lon_rad)
        if np.any(lat_ok != lon_ok):
            n = int(np.sum(lat_ok != lon_ok))
            raise GranuleError(
                path,
                f"{product.data_group}/Longitude",
                f"fill at {n} pixel(s) where Latitude is set, or set where it is fill",
            )
    if isinstance(granule, ViirsGeoGranule) and granule.height_m is not None and "height_m" in product.fields:
        check_height(
            path,
            f"{product.data_group}/{product.fields['height_m'].dataset}",
            granule.lat_rad,
            granule.lon_rad,
            granule.height_m,
        )


def check_height(
    path: GranuleRef, name: str, lat_rad: np.ndarray, lon_rad: np.ndarray, height_m: np.ndarray
) -> None:
    """A terrain-corrected pixel needs its height: fill only where the pixel itself is fill.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    name : str
        The dataset.
    lat_rad, lon_rad : numpy.ndarray
        The pixels' latitude and longitude, rad (NaN: fill).
    height_m : numpy.ndarray
        Their height, m.
    """
    located = np.isfinite(lat_rad) & np.isfinite(lon_rad)
    missing = located & ~np.isfinite(height_m)
    if missing.any():
        r, c = np.argwhere(missing)[0]
        raise GranuleError(
            path,
            name,
            f"fill or non-finite at {int(missing.sum())} geolocated pixel(s), first at row {r}, column {c}",
        )
    bad = located & ((height_m < -500.0) | (height_m > 9000.0))
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise GranuleError(
            path,
            name,
            f"terrain height {float(height_m[r, c]):.6g} m at row {r}, column {c} is outside -500..9000 m",
        )
