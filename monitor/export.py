"""Results as data for scientists: the store's per-FOR offsets as a CF-style xarray Dataset, NetCDF or CSV.

Dimensions ``time`` (the assessed day, 00:00 UTC) x ``for`` (scan position 1..30); one variable per stored
quantity with its unit and long name, the reliability flags as a CF bit mask (``flag_masks`` and
``flag_meanings``), and global attributes for the satellite, the method and the software version.
xarray and h5netcdf are an optional extra: ``pip install 'crisgeo-monitor[export]'``.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np

from monitor.constants import N_FOR
from monitor.result import RELIABILITY_FLAGS
from monitor.satellites import satellite as satellite_info

# variable: (unit, long name); the store's column names
VARIABLES = {
    "d_alpha_urad": ("urad", "in-track LOS offset (turn of the CrIS LOS that best matches VIIRS I5)"),
    "d_beta_urad": ("urad", "cross-track LOS offset"),
    "sigma_alpha_urad": ("urad", "uncertainty (1 sigma) of the in-track offset"),
    "sigma_beta_urad": ("urad", "uncertainty (1 sigma) of the cross-track offset"),
    "in_track_km": ("km", "in-track geolocation error on the ground"),
    "cross_track_km": ("km", "cross-track geolocation error on the ground"),
    "total_km": ("km", "total geolocation error on the ground"),
    "sigma_in_track_km": ("km", "uncertainty (1 sigma) of the in-track error"),
    "sigma_cross_track_km": ("km", "uncertainty (1 sigma) of the cross-track error"),
    "cost_min_k": ("K", "minimum of the cost STDEV(BT_VIIRS - BT_CrIS) over the perturbations"),
    "cost_zero_k": ("K", "cost STDEV(BT_VIIRS - BT_CrIS) of the unperturbed LOS"),
}
FLAG_BITS = {name: 1 << i for i, name in enumerate(RELIABILITY_FLAGS)}


def to_xarray(store, satellite: str, since: dt.date | None = None, until: dt.date | None = None):
    """The per-FOR results of *satellite* between *since* and *until* (inclusive) as an xarray Dataset."""
    import xarray as xr

    from monitor.version import __version__

    series = store.series(satellite, since, until)
    data = {k: series.values[k] for k in VARIABLES}
    n_samples = series.values["n_samples"].astype(np.int32)
    bits = np.vectorize(lambda f: sum(FLAG_BITS.get(x, 0) for x in f), otypes=[np.int8])
    flags = bits(series.flags) if series.flags.size else np.zeros(series.flags.shape, np.int8)
    coords = {
        "time": np.array([np.datetime64(d.isoformat(), "ns") for d in series.days], dtype="datetime64[ns]"),
        "for": np.arange(1, N_FOR + 1, dtype=np.int16),
    }
    ds = xr.Dataset(
        {
            name: (("time", "for"), data[name], {"units": unit, "long_name": long})
            for name, (unit, long) in VARIABLES.items()
        },
        coords=coords,
    )
    ds["n_samples"] = (
        ("time", "for"),
        n_samples,
        {"units": "1", "long_name": "CrIS FOVs in the cost function"},
    )
    ds["flags"] = (
        ("time", "for"),
        flags,
        {
            "long_name": "reliability flags (any set: not reliable)",
            "flag_masks": np.array(list(FLAG_BITS.values()), np.int8),
            "flag_meanings": " ".join(FLAG_BITS),
        },
    )
    ds["for"].attrs.update(long_name="CrIS field of regard (scan position)", units="1")
    ds["time"].attrs.update(long_name="assessed day (00:00 UTC)")
    info = satellite_info(satellite)
    ds.attrs.update(
        Conventions="CF-1.8",
        title=f"CrIS geolocation assessed against VIIRS I5, {info.name}",
        satellite=satellite,
        platform=info.name,
        method="LOS perturbation assessment, Wang et al. 2017, JGR 122:519",
        source=f"crisgeo-monitor {__version__}",
        history=f"{dt.datetime.now(dt.timezone.utc):%Y-%m-%dT%H:%M:%SZ} exported from {store.path.name}",
    )
    return ds


def export(store, satellite: str, out, fmt: str, since=None, until=None) -> Path:
    """Write the results of *satellite* to *out* as ``netcdf`` or ``csv``; returns the path."""
    out = Path(out)
    ds = to_xarray(store, satellite, since, until)
    tmp = out.with_name(out.name + ".part")
    if fmt == "netcdf":
        ds.to_netcdf(tmp, engine="h5netcdf")
    elif fmt == "csv":
        ds.to_dataframe().reset_index().to_csv(tmp, index=False)
    else:
        raise ValueError(f"export format {fmt!r} is not netcdf or csv")
    tmp.replace(out)
    return out
