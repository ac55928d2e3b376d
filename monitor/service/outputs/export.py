"""Results as data for scientists: the store's per-FOR offsets as a CF-1.8 / ACDD-1.3 xarray Dataset,
NetCDF or CSV.

Dimensions ``time`` (the assessed day: its start, with ``time_bnds`` the whole UTC day; first and unlimited,
so that daily files append along it) x ``scan_position`` (the CrIS field of regard, 1..30; a name Python
accepts: ``ds.sel(scan_position=1)``); one variable per stored quantity with its unit, long name and ACDD
``coverage_content_type``, every flag of the table as a CF bit mask (``flag_masks`` and ``flag_meanings``),
the sign convention stated once (the global attribute ``sign_convention``), and the ACDD global attributes
(title, summary, references to the method paper, history, date_created, time coverage, platform,
instrument, source, id; institution, creator, license and the like from the ``export`` section of the
configuration). The compliance checker's CF-1.8 check passes, and its ACDD-1.3 check leaves only what
does not apply (tests/service/outputs/test_export.py): no CF standard name exists for these quantities,
and the file is per scan position, not per place (no geospatial bounds). xarray and h5netcdf are an
optional extra: ``pip install 'crisgeo-monitor[export]'``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Self

if TYPE_CHECKING:
    import xarray as xr

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from alerts.effects import ChangeEffect
from monitor.config.model import Config
from monitor.config.outputs import ExportConfig
from monitor.core.bands import BANDS
from monitor.core.constants import DEFAULT_HALF_STEPS, N_FOR, SPEC_KM
from monitor.core.measures import Measure
from monitor.core.result import FLAGS, ForOffset, measures
from monitor.core.satellites import satellite as satellite_info
from monitor.history.records import History
from monitor.service.store.sqlite import Store
from monitor.version import __version__

SIGN_CONVENTION = (
    "d_alpha_urad and d_beta_urad are the turn of the CrIS line of sight reported by the GEO product (in "
    "the spacecraft body frame: alpha in-track, beta cross-track) that best aligns CrIS with VIIRS I5; "
    "in_track_km and cross_track_km are the displacement on the ground that turn makes (positive along "
    "the flight direction and to the right of it). Both are what this product calls the geolocation "
    "error: the correction to add to the reported geolocation."
)
FORMATS = {".nc": "netcdf", ".nc4": "netcdf", ".csv": "csv"}  # the suffix of --out says the format
FLAG_BITS = {name: 1 << i for i, name in enumerate(FLAGS)}  # every flag the table shows


class ResultStore:
    """The store as a notebook opens it (:func:`monitor.open_store`): its results as xarray, over the
    SQLite store (``.store``); a context manager that closes it.

    Parameters
    ----------
    store : Store
        The SQLite store.
    """

    def __init__(self, store: Store) -> None:
        self.store = store

    def to_xarray(
        self, satellite: str, since: dt.date | None = None, until: dt.date | None = None
    ) -> xr.Dataset:
        """The per-FOR results of *satellite* as a CF-style xarray Dataset.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        since, until : datetime.date, optional
            The first and last day, inclusive; None: open.

        Returns
        -------
        xarray.Dataset
            As :func:`to_xarray`.
        """
        return to_xarray(self.store, satellite, since, until)

    def close(self) -> None:
        """Close the store."""
        self.store.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass(frozen=True)
class Method:
    """What the export's metadata says of how the results were made, from the configuration.

    Attributes
    ----------
    half_steps : int
        Perturbations on each side of zero per direction (``assessment.half_steps``).
    spec_km : float
        The specification of the geolocation error on the ground, km (``alerts.spec_km``).
    """

    half_steps: int = DEFAULT_HALF_STEPS
    spec_km: float = SPEC_KM

    @classmethod
    def of(cls, cfg: Config) -> Method:
        """The grid and specification of the configuration *cfg*.

        Parameters
        ----------
        cfg : Config
            The configuration.

        Returns
        -------
        Method
            Its grid and specification.
        """
        return cls(cfg.assessment.half_steps, cfg.alerts.spec_km)

    @property
    def grid(self) -> str:  # numpydoc ignore=RT01
        """The perturbation grid, ``21 x 21`` at the defaults."""
        n = 2 * self.half_steps + 1
        return f"{n} x {n}"


def _attrs(m: Measure, meaning: str | None = None) -> dict:
    """A variable's attributes from its field's declaration (*meaning*: its long name, where not the
    declaration's)."""
    return {
        "units": m.unit,
        "long_name": meaning or m.meaning,
        "coverage_content_type": "qualityInformation" if m.quality else "physicalMeasurement",
    }


def to_xarray(
    store: History,
    satellite: str,
    since: dt.date | None = None,
    until: dt.date | None = None,
    publisher: ExportConfig | None = None,
    record: type = ForOffset,
    method: Method | None = None,
) -> xr.Dataset:
    """The per-FOR results of *satellite* between *since* and *until* (inclusive) as an xarray Dataset, a
    variable per measured field of *record* with the unit and meaning it declares.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name (``j01``).
    since, until : datetime.date, optional
        The first and last day (inclusive); None for the store's first or last.
    publisher : ExportConfig, optional
        The ``export`` section of the configuration: the ACDD publisher attributes.
    record : type, optional
        The per-FOR record whose measured fields become variables.
    method : Method, optional
        The configured grid and specification the metadata states (:meth:`Method.of`); the defaults when
        None.

    Returns
    -------
    xarray.Dataset
        Dimensions ``time`` x ``scan_position``, CF-1.8 and ACDD-1.3 attributes.
    """
    import xarray as xr

    method = method or Method()
    series = store.series(satellite, since, until)
    bits = np.vectorize(lambda f: sum(FLAG_BITS.get(x, 0) for x in f), otypes=[np.int16])
    flags = bits(series.flags) if series.flags.size else np.zeros(series.flags.shape, np.int16)
    days = np.array([np.datetime64(d.isoformat(), "ns") for d in series.days], dtype="datetime64[ns]")
    declared = measures(record)
    # the bands by wavelength: a CF coordinate variable is numeric and monotonic, the names are its labels
    bands = tuple(sorted({m.band for m in declared if m.band is not None}, key=lambda b: BANDS[b].centre_um))
    coords: dict[str, Any] = {"time": days, "scan_position": np.arange(1, N_FOR + 1, dtype=np.int16)}
    if bands:
        coords["band"] = np.array([BANDS[b].centre_um for b in bands])
        coords["band_name"] = ("band", np.array(bands, dtype=object), {"long_name": "VIIRS band"})
    dims = ("time", "scan_position")  # time first and unlimited: daily files append along it
    variables: dict[str, tuple[tuple[str, ...], np.ndarray, dict]] = {
        m.name: (dims, series.values[m.name].astype(np.int32 if m.kind is int else np.float64), _attrs(m))
        for m in declared
        if m.band is None
    }
    # a field measured per band is one variable on the band dimension, named without its band
    for quantity in dict.fromkeys(m.quantity for m in declared if m.band is not None):
        per_band = {m.band: m for m in declared if m.band is not None and m.quantity == quantity}
        first = per_band[next(iter(per_band))]
        stacked = np.stack(
            [
                series.values[per_band[b].name] if b in per_band else np.full(flags.shape, np.nan)
                for b in bands
            ],
            axis=-1,
        )
        meaning = first.meaning.replace(f" {first.band} ", " ")
        variables[quantity] = ((*dims, "band"), stacked.astype(np.float64), _attrs(first, meaning))
    ds = xr.Dataset(variables, coords=coords)
    if bands:
        ds["band"].attrs.update(
            standard_name="sensor_band_central_radiation_wavelength",
            units="um",
            long_name="VIIRS band's nominal central wavelength (band_name: its name)",
            coverage_content_type="coordinate",
        )
        ds["band"].encoding["_FillValue"] = None  # a coordinate variable has no missing values
    ds["time_bnds"] = (("time", "nv"), np.stack([days, days + np.timedelta64(1, "D")], axis=-1))
    ds["flags"] = (
        dims,
        flags,
        {
            "long_name": "flags (any of the first four set: not reliable)",
            "flag_masks": np.array(list(FLAG_BITS.values()), np.int16),
            "flag_meanings": " ".join(FLAG_BITS),
            "coverage_content_type": "qualityInformation",
        },
    )
    ds["scan_position"].attrs.update(
        long_name="CrIS field of regard (scan position, 1 = first of the scan)",
        coverage_content_type="coordinate",
    )
    ds["time"].attrs.update(
        standard_name="time",
        axis="T",
        long_name="assessed UTC day (its start)",
        bounds="time_bnds",
        coverage_content_type="coordinate",
    )
    ds["time"].encoding.update(units="days since 1970-01-01 00:00:00", calendar="standard", dtype="int32")
    ds["time_bnds"].encoding.update(
        units="days since 1970-01-01 00:00:00", calendar="standard", dtype="int32"
    )
    ds.attrs.update(
        _identity(
            satellite,
            f"CrIS geolocation assessed against VIIRS I5, {satellite_info(satellite).name}",
            "Daily per-field-of-regard offsets of the CrIS line of sight (in-track alpha, cross-track beta, "
            "urad) and the geolocation errors on the ground (km), found by perturbing the CrIS line of sight "
            f"{method.grid} times per FOV, collocating VIIRS I5 pixels in each perturbed footprint and "
            "minimising a cost of the CrIS minus VIIRS brightness temperature differences.",
            f"from {store.path.name}",
        ),
        comment=(
            "One value per assessed UTC day and CrIS scan position; flags set mark values not to be trusted "
            f"(few samples, grid edge, flat cost, uncertain). The specification is {method.spec_km:g} km "
            "in-track and cross-track, each."
        ),
        acknowledgement=(
            "CrIS and VIIRS SDR and GEO granules of NOAA's JPSS, from the NOAA Open Data Dissemination "
            "archive; the method of Wang et al. (2017)."
        ),
        id=f"crisgeo_{satellite}",
        standard_name_vocabulary="CF Standard Name Table v79",
        time_coverage_resolution="P1D",
        references=(
            "Wang, L., B. Zhang, D. Tremblay, and Y. Han (2017), Improved scheme for Cross-track Infrared "
            "Sounder geolocation assessment and optimization, J. Geophys. Res. Atmos., 122, 519-536, "
            "doi:10.1002/2016JD025812"
        ),
        keywords="CrIS, VIIRS, geolocation, line of sight, JPSS, calibration",
        method="LOS perturbation assessment, Wang et al. 2017, JGR 122:519",
        processing_level="L2 monitoring product (from CrIS SDR/GEO and VIIRS I5 SDR/GEO)",
        product_version=__version__,
    )
    if series.days:
        first, last = series.days[0], series.days[-1]
        ds.attrs.update(
            id=f"crisgeo_{satellite}_{first:%Y%m%d}_{last:%Y%m%d}",
            # ACDD: the times of the first and last data points, each stamped at its day's start (the
            # days themselves are in time_bnds)
            time_coverage_start=f"{first:%Y-%m-%d}T00:00:00Z",
            time_coverage_end=f"{last:%Y-%m-%d}T00:00:00Z",
            time_coverage_duration=f"P{(last - first).days + 1}D",
        )
    _publish(ds, publisher)
    return ds


def _identity(satellite: str, title: str, summary: str, origin: str = "") -> dict[str, str]:
    """The global attributes every export carries: the conventions, its *title* and *summary*, the sign
    convention, the platform and instruments, the software and when it was made (from *origin*)."""
    now = f"{dt.datetime.now(dt.timezone.utc):%Y-%m-%dT%H:%M:%SZ}"
    return {
        "Conventions": "CF-1.8, ACDD-1.3",
        "title": title,
        "summary": summary,
        "sign_convention": SIGN_CONVENTION,
        "platform": satellite_info(satellite).name,
        "instrument": "CrIS, VIIRS",
        "satellite": satellite,
        "source": f"crisgeo-monitor {__version__}",
        "date_created": now,
        "history": f"{now} exported {origin + ' ' if origin else ''}by crisgeo-monitor {__version__}",
    }


def _publish(ds: xr.Dataset, publisher: ExportConfig | None) -> None:
    """The ACDD creator and publisher attributes from the ``export`` section of the configuration."""
    if publisher is not None:
        ds.attrs.update({k: str(v) for k, v in publisher.model_dump().items() if v is not None})
        if publisher.creator_name:  # the team that makes the data publishes it
            ds.attrs.update(
                publisher_name=publisher.creator_name,
                **({"publisher_email": publisher.creator_email} if publisher.creator_email else {}),
                **({"publisher_url": str(publisher.creator_url)} if publisher.creator_url else {}),
            )


# what a change did, per direction (alerts.effects.ChangeEffect): (variable stem, attribute, unit, meaning)
EFFECT_FIELDS = (
    ("before", "before_urad", "urad", "offset over the days before the change"),
    ("sigma_before", "sigma_before_urad", "urad", "1-sigma uncertainty of the offset before the change"),
    ("after", "after_urad", "urad", "offset over the days after the change"),
    ("sigma_after", "sigma_after_urad", "urad", "1-sigma uncertainty of the offset after the change"),
    ("move", "move_urad", "urad", "offset after minus before"),
    ("sigma_move", "sigma_move_urad", "urad", "1-sigma uncertainty of the move"),
    ("move_ground", "move_km", "km", "the move on the ground"),
    ("sigma_move_ground", "sigma_move_km", "km", "1-sigma uncertainty of the move on the ground"),
    ("predicted", "predicted_urad", "urad", "the move the EPs' mapping angles predict"),
)
DIRECTION_NAMES = (("alpha", "in-track"), ("beta", "cross-track"))


def effects_to_xarray(
    effects: Sequence[ChangeEffect], satellite: str, publisher: ExportConfig | None = None
) -> xr.Dataset:
    """What each known change did (:mod:`alerts.effects`) as an xarray Dataset: dimensions ``change`` (its
    day, its description) x ``scan_position``, a variable per quantity and direction (e.g.
    ``move_alpha_urad``), ``significant_alpha`` and ``significant_beta`` as 0/1 flags, and per change the
    windows, the EPs and the chi-square of the prediction.

    Parameters
    ----------
    effects : sequence of ChangeEffect
        What each known change did.
    satellite : str
        The satellite's short name.
    publisher : ExportConfig, optional
        The ``export`` section: the ACDD publisher attributes.

    Returns
    -------
    xarray.Dataset
        Dimensions ``change`` x ``scan_position``.
    """
    import xarray as xr

    def per_direction(attr: str, c: int) -> np.ndarray:
        rows = [getattr(e, attr) for e in effects]
        return np.array([np.full(N_FOR, np.nan) if r is None else r[:, c] for r in rows], np.float64)

    dims = ("change", "scan_position")
    data: dict[str, tuple] = {}
    for c, (angle, direction) in enumerate(DIRECTION_NAMES):
        for stem, attr, unit, meaning in EFFECT_FIELDS:
            unit_name = "km" if unit == "km" else "urad"
            data[f"{stem}_{angle}_{unit_name}"] = (
                dims,
                per_direction(attr, c),
                {"units": unit, "long_name": f"{direction} {meaning}"},
            )
        data[f"significant_{angle}"] = (
            dims,
            np.array([e.significant[:, c] for e in effects], np.int8).reshape(len(effects), N_FOR),
            {
                "long_name": f"{direction} move beyond z_limit sigmas",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "not_significant significant",
            },
        )
    text = lambda values: np.array(values, dtype=object)  # noqa: E731
    span = lambda w: f"{w[0]}/{w[1]}" if w else ""  # noqa: E731
    data |= {
        "description": (("change",), text(["; ".join(c.label() for c in e.changes) for e in effects]), {
            "long_name": "the known changes of the day"}),
        "before_days": (("change",), text([span(e.before) for e in effects]), {
            "long_name": "first/last assessed day before the change"}),
        "after_days": (("change",), text([span(e.after) for e in effects]), {
            "long_name": "first/last assessed day after the change"}),
        "z_limit": (("change",), np.array([e.z_limit for e in effects]), {
            "units": "1", "long_name": "sigmas beyond which a move is significant"}),
        "ep_before": (("change",), text([e.ep_before or "" for e in effects]), {
            "long_name": "the EP the LOS fingerprint before the change names"}),
        "ep_after": (("change",), text([e.ep_after or "" for e in effects]), {
            "long_name": "the EP the LOS fingerprint after the change names"}),
        "chi2": (("change",), np.array([e.chi2 for e in effects]), {
            "units": "1", "long_name": "chi-square of observed minus predicted moves"}),
        "chi2_dof": (("change",), np.array([e.dof for e in effects], np.int32), {
            "units": "1", "long_name": "FOR-directions in the chi-square"}),
    }  # fmt: skip
    ds = xr.Dataset(
        data,
        coords={
            "change": np.array([np.datetime64(e.day.isoformat(), "ns") for e in effects], "datetime64[ns]"),
            "scan_position": np.arange(1, N_FOR + 1, dtype=np.int16),
        },
    )
    ds["change"].attrs.update(long_name="UTC day of the known change", axis="T")
    ds["change"].encoding.update(units="days since 1970-01-01 00:00:00", calendar="standard", dtype="int32")
    ds["scan_position"].attrs.update(long_name="CrIS field of regard (scan position, 1 = first of the scan)")
    ds.attrs.update(
        _identity(
            satellite,
            "What each known change did to the CrIS geolocation against VIIRS I5, "
            + satellite_info(satellite).name,
            "Per known change (EP upload, LUT change, software) and CrIS field of regard: the offsets before "
            "and after with sigmas, the move and its significance, and the move the EPs' mapping angles "
            "predict (crisgeo events effects; docs/operations.md).",
        )
    )
    _publish(ds, publisher)
    return ds


class NothingToExport(ValueError):
    """The store holds no results in the period asked for."""


class ExportFormatError(ValueError):
    """The format asked for and the name of the file disagree, or neither says one."""


def export(
    store: History,
    satellite: str,
    out: str | Path,
    fmt: str | None = None,
    since: dt.date | None = None,
    until: dt.date | None = None,
    publisher: ExportConfig | None = None,
    method: Method | None = None,
) -> Path:
    """Write the results of *satellite* to *out* as ``netcdf`` or ``csv`` (*fmt*; None: from the suffix of
    *out*, :data:`FORMATS`); returns the path. :class:`NothingToExport` (and no file) when the period holds
    no results, :class:`ExportFormatError` when the format and the file's name disagree; :class:`OSError`
    when *out* cannot be written.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    out : str or Path
        The file.
    fmt : str, optional
        ``netcdf`` or ``csv``; None: from the suffix of *out*.
    since, until : datetime.date, optional
        The first and last day, inclusive; None: open.
    publisher : ExportConfig, optional
        The ``export`` section: the ACDD publisher attributes.
    method : Method, optional
        The grid and specification the metadata states.

    Returns
    -------
    Path
        The file written.
    """
    out, fmt = _target(out, fmt)
    ds = to_xarray(store, satellite, since, until, publisher, method=method)
    if ds.sizes["time"] == 0:
        period = f"{since or 'the beginning'} .. {until or 'the end'}"
        raise NothingToExport(f"no results of {satellite} in {period}: nothing written")
    return _write(ds, out, fmt, "time", drop=("time_bnds",))


def export_effects(
    effects: Sequence[ChangeEffect],
    satellite: str,
    out: str | Path,
    fmt: str | None = None,
    publisher: ExportConfig | None = None,
) -> Path:
    """Write what each known change did (*effects*, :func:`alerts.effects.change_effects`) to *out* as
    ``netcdf`` or ``csv`` (:func:`effects_to_xarray`; CSV: a row per change and FOR); the errors of
    :func:`export`.

    Parameters
    ----------
    effects : sequence of ChangeEffect
        What each known change did.
    satellite : str
        The satellite's short name.
    out : str or Path
        The file.
    fmt : str, optional
        ``netcdf`` or ``csv``; None: from the suffix of *out*.
    publisher : ExportConfig, optional
        The ``export`` section: the ACDD publisher attributes.

    Returns
    -------
    Path
        The file written.
    """
    out, fmt = _target(out, fmt)
    if not effects:
        raise NothingToExport(
            f"no known change of {satellite} with assessed days on both sides: nothing written"
        )
    return _write(effects_to_xarray(effects, satellite, publisher), out, fmt, "change")


def _target(out: str | Path, fmt: str | None) -> tuple[Path, str]:
    """The file and its format: *fmt*, else the suffix of *out* (:data:`FORMATS`); they must agree, and the
    folder must exist."""
    out = Path(out)
    by_suffix = FORMATS.get(out.suffix.lower())
    if fmt is None and by_suffix is None:
        raise ExportFormatError(f"--out {out}: name it .nc or .csv, or give --format")
    if fmt is not None and by_suffix is not None and fmt != by_suffix:
        raise ExportFormatError(f"--out {out}: a {out.suffix} file cannot hold --format {fmt}")
    if not out.parent.is_dir():
        raise FileNotFoundError(f"the folder {out.parent} does not exist")
    return out, fmt or str(by_suffix)


def _band_columns(ds: xr.Dataset) -> xr.Dataset:
    """*ds* with each variable on the band dimension as a variable per band (``cris_minus_viirs_k_M15``,
    the stored name): a table keeps a row per day and FOR."""
    if "band" not in ds.dims:
        return ds
    stacked = [v for v in ds.data_vars if "band" in ds[v].dims]
    names = [str(n) for n in ds["band_name"].values]
    wide = {f"{v}_{b}": ds[v].isel(band=i, drop=True) for v in stacked for i, b in enumerate(names)}
    return ds.drop_vars([*stacked, "band", "band_name"]).assign(wide)


def _write(ds: xr.Dataset, out: Path, fmt: str, unlimited: str, drop: tuple[str, ...] = ()) -> Path:
    """*ds* to *out* through a partial file (a reader never sees half of it), the dimension *unlimited*
    first and unlimited in NetCDF (later files append along it); CSV without the *drop* variables (bounds,
    which a table cannot hold)."""
    tmp = out.with_name(out.name + ".part")
    if fmt == "netcdf":
        ds.to_netcdf(tmp, engine="h5netcdf", unlimited_dims=[unlimited])
    else:
        ds.drop_vars(list(drop)).pipe(_band_columns).to_dataframe().reset_index().to_csv(tmp, index=False)
    tmp.replace(out)
    return out
