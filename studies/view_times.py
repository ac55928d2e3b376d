"""How long after CrIS VIIRS sees the same ground, per FOV row: what a wind turns into an offset.

A cloud carried at u m/s along the track between the two views is seen by VIIRS u x (t_VIIRS - t_CrIS)
metres further on than CrIS saw it, and the collocation turns that into an offset of the CrIS LOS. This
bench reads a case's GEO files (CrIS GCRSO FORTime and FOV positions, VIIRS GITCO positions and scan
start times with each column's time from the scan's start, ``monitor.simulate.scan_geometry``), matches
each FOV centre to the nearest VIIRS pixel and prints, per row (FOVs 7-9 ahead, 4-6, 1-3 behind), the
median and range of t_VIIRS - t_CrIS (s), and what a wind of 1 m/s makes of the rows ahead minus behind
at the FOV's range (urad). Prints one JSON row.

    .venv/bin/python -m studies.view_times CASE_DIR [--rows FILE]

A case directory is one ``crisgeo simulate`` wrote (the simulator's VIIRS column times; a real GITCO's
would be read from its own scan timing).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import h5py
import numpy as np
from scipy.spatial import cKDTree

from benchmarks.provenance import commit, emit
from monitor.geometry.wgs84 import geodetic_to_ecef
from monitor.sdr import iet
from monitor.simulate import scan_geometry as ins

ROWS = {"ahead": (6, 7, 8), "centre": (3, 4, 5), "behind": (0, 1, 2)}  # FOV index 0..8


def view_times(case: Path) -> dict:
    """The row of one case (module docstring)."""
    _, col_dt = ins.viirs_column_geometry()
    lags, ranges = [], []
    for geo_path in sorted(case.glob("GCRSO*.h5")):
        with h5py.File(geo_path) as f:
            g = f["All_Data/CrIS-SDR-GEO_All"]
            for_s = iet.iet_to_unix_us(g["FORTime"][()]) * 1e-6
            lat, lon, rng_m = g["Latitude"][()], g["Longitude"][()], g["SatelliteRange"][()]
        lags.append(np.full(lat.shape, np.nan))
        ranges.append(rng_m)
        for viirs_path in sorted(case.glob("GITCO*.h5")):
            with h5py.File(viirs_path) as f:
                v = f["All_Data/VIIRS-IMG-GEO-TC_All"]
                vlat, vlon = v["Latitude"][()], v["Longitude"][()]
                start = iet.iet_to_unix_us(v["StartTime"][()]) * 1e-6
            pixel_s = np.repeat(start, vlat.shape[0] // len(start))[:, None] + col_dt[None, :]
            ok = np.abs(vlat) <= 90.0
            tree = cKDTree(geodetic_to_ecef(np.radians(vlat[ok]), np.radians(vlon[ok])))
            dist_m, idx = tree.query(geodetic_to_ecef(np.radians(lat), np.radians(lon)).reshape(-1, 3))
            near = (dist_m < 400.0).reshape(lat.shape)  # within a pixel: this granule holds it
            lag = pixel_s[ok][idx].reshape(lat.shape) - for_s[:, :, None]
            lags[-1] = np.where(near, lag, lags[-1])
    lag, rng = np.concatenate(lags), np.concatenate(ranges)
    row: dict = {"commit": commit(), "case": str(case)}
    for name, fovs in ROWS.items():
        x = lag[..., list(fovs)]
        row[f"{name}_s"] = {
            "median": float(np.nanmedian(x)),
            "min": float(np.nanmin(x)),
            "max": float(np.nanmax(x)),
        }
    apart = (lag[..., list(ROWS["ahead"])].mean(-1) - lag[..., list(ROWS["behind"])].mean(-1)) / rng.mean(-1)
    row["rows_urad_per_m_s"] = float(np.nanmedian(apart) * 1e6)
    return row


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case", type=Path)
    p.add_argument("--rows", help="append the JSON row here")
    args = p.parse_args()
    emit(view_times(args.case), args.rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
