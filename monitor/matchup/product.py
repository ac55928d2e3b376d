"""The CrIS-VIIRS mapping as a product: every CrIS FOV's VIIRS scene and CrIS brightness temperature per
band, as a CF-1.8 / ACDD-1.3 NetCDF file that xarray opens.

Dimensions ``band`` (labels ``I5``, ``M13``, ``M15``, ``M16``: those mapped), ``scan`` (every CrIS scan
of the granules mapped, in time order), ``scan_position`` (the field of regard, 1..30; the name the
results' export uses) and ``fov`` (1..9). Each variable is declared once in :data:`VARIABLES` with its
unit and meaning; the global attribute ``geolocation`` says whether the FOVs stand where the GEO product
puts them (``operational``) or where a day's assessment found them (``assessed``). xarray and h5netcdf
are the ``export`` extra, as for the results' export.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from monitor.core.constants import N_FOR, N_FOV
from monitor.core.satellites import satellite as satellite_info
from monitor.version import __version__

if TYPE_CHECKING:
    import xarray as xr

IET_EPOCH = "1958-01-01T00:00:00"


@dataclass(frozen=True)
class Variable:
    """One variable of the mapping file: its unit, long name and ACDD content type."""

    units: str
    long_name: str
    content: str = "physicalMeasurement"


# the per-band variables (band, scan, scan_position, fov)
VARIABLES = {
    "viirs_bt_k": Variable(
        "K",
        "brightness temperature of the VIIRS band radiance averaged over the CrIS FOV, each pixel "
        "weighted by the CrIS spatial response times the solid angle it covers",
    ),
    "viirs_bt_std_k": Variable(
        "K", "response-weighted standard deviation of the VIIRS pixels' brightness temperature in the FOV"
    ),
    "viirs_pixels": Variable("1", "valid VIIRS pixels inside the FOV's response", "auxiliaryInformation"),
    "viirs_valid_fraction": Variable(
        "1", "share of the response's weight that valid VIIRS pixels cover", "qualityInformation"
    ),
    "cris_bt_k": Variable(
        "K",
        "brightness temperature of the CrIS spectrum (Hamming apodized) convolved with the VIIRS band's "
        "spectral response, by the band-integrated Planck function of the same response",
    ),
}


@dataclass
class Matchup:
    """The mapping of a set of CrIS granules: per band, scan, FOR and FOV (:data:`VARIABLES`), with each
    scan's time and each FOV's place; ``notes`` say what could not be mapped and why."""

    satellite: str
    bands: tuple[str, ...]
    geolocation: str  # "operational" or "assessed"
    response: str  # "nominal" or "fitted"
    time_iet_us: np.ndarray  # (scan, 30) each FOR's time
    latitude_deg: np.ndarray  # (scan, 30, 9)
    longitude_deg: np.ndarray
    values: dict[str, np.ndarray]  # name -> (band, scan, 30, 9)
    granules: list[str] = field(default_factory=list)  # the CrIS SDR files mapped, in time order
    granule_of_scan: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))  # index in granules
    notes: list[str] = field(default_factory=list)

    @property
    def scans(self) -> int:  # numpydoc ignore=RT01
        """The CrIS scans mapped."""
        return int(self.time_iet_us.shape[0])

    def to_xarray(self) -> xr.Dataset:
        """The mapping as a CF-1.8 / ACDD-1.3 xarray Dataset.

        Returns
        -------
        xarray.Dataset
            Dimensions band, scan, scan_position, fov.
        """
        import xarray as xr

        from monitor.sdr.iet import iet_to_unix_us

        dims = ("band", "scan", "scan_position", "fov")
        unix_us = iet_to_unix_us(self.time_iet_us.astype(np.int64))
        times = np.where(self.time_iet_us > 0, unix_us, 0).astype("datetime64[us]")
        data_vars = {
            name: (
                dims,
                self.values[name].astype(np.float32 if name != "viirs_pixels" else np.int32),
                {
                    "units": v.units,
                    "long_name": v.long_name,
                    "coverage_content_type": v.content,
                },
            )
            for name, v in VARIABLES.items()
        }
        ds = xr.Dataset(
            data_vars,
            coords={
                "band": ("band", np.array(self.bands, dtype=object), {"long_name": "VIIRS band"}),
                "scan": (
                    "scan",
                    np.arange(self.scans, dtype=np.int32),
                    {"long_name": "CrIS scan, in time order"},
                ),
                "scan_position": (
                    "scan_position",
                    np.arange(1, N_FOR + 1, dtype=np.int32),
                    {"long_name": "CrIS field of regard (scan position)"},
                ),
                "fov": ("fov", np.arange(1, N_FOV + 1, dtype=np.int32), {"long_name": "CrIS field of view"}),
                "time": (
                    ("scan", "scan_position"),
                    times,
                    {"long_name": "time of the field of regard", "standard_name": "time"},
                ),
                "latitude": (
                    ("scan", "scan_position", "fov"),
                    self.latitude_deg.astype(np.float32),
                    {
                        "units": "degrees_north",
                        "standard_name": "latitude",
                        "long_name": "FOV centre latitude",
                    },
                ),
                "longitude": (
                    ("scan", "scan_position", "fov"),
                    self.longitude_deg.astype(np.float32),
                    {
                        "units": "degrees_east",
                        "standard_name": "longitude",
                        "long_name": "FOV centre longitude",
                    },
                ),
            },
        )
        for name in VARIABLES:
            ds[name].attrs["coordinates"] = "time latitude longitude"
        # CF wants a floating or 32-bit time: seconds, the microseconds kept in the float64's fraction
        ds["time"].encoding.update(
            units="seconds since 1970-01-01 00:00:00", calendar="standard", dtype="float64"
        )
        valid = times[self.time_iet_us > 0]
        now = dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        sat = satellite_info(self.satellite)
        ds.attrs = {
            "Conventions": "CF-1.8, ACDD-1.3",
            "title": f"CrIS FOVs mapped onto VIIRS {', '.join(self.bands)}, {sat.name}",
            "summary": (
                "For every CrIS field of view: the VIIRS scene inside it in each band (the response-weighted "
                "mean radiance as a brightness temperature, its spread, its pixels and coverage) and CrIS "
                "convolved with the band's spectral response."
            ),
            "geolocation": self.geolocation,
            "geolocation_comment": (
                "assessed: each FOV's line of sight turned by its FOR's offsets from a crisgeo assessment; "
                "operational: as the CrIS GEO product puts it"
            ),
            "spatial_response": self.response,
            "platform": sat.name,
            "instrument": "CrIS, VIIRS",
            "source": ", ".join(self.granules[:50]) + (" ..." if len(self.granules) > 50 else ""),
            "history": f"{now} crisgeo map {__version__}",
            "date_created": now,
            "time_coverage_start": str(valid.min()) + "Z" if valid.size else "",
            "time_coverage_end": str(valid.max()) + "Z" if valid.size else "",
            "references": (
                "Wang et al. 2017, doi:10.1002/2016JD025812; Tobin et al. 2013, doi:10.1002/jgrd.50652"
            ),
            "processing_notes": "; ".join(self.notes),
        }
        return ds

    def write(self, path: str | Path) -> Path:
        """Write the NetCDF file (h5netcdf), atomically: a reader never sees half of it.

        Parameters
        ----------
        path : str or Path
            The file.

        Returns
        -------
        Path
            The file written.
        """
        out = Path(path)
        tmp = out.with_name(out.name + ".part")
        self.to_xarray().to_netcdf(tmp, engine="h5netcdf")
        tmp.replace(out)
        return out
