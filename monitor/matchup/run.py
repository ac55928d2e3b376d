"""Map CrIS granules onto VIIRS: each FOV's VIIRS scene and CrIS brightness temperature in every band.

The files given are paired as the assessment pairs them (:func:`monitor.sdr.pairing.plan`): each CrIS
SDR with its GEO, each VIIRS band's SDR with its grid's GEO, the VIIRS granules covering a CrIS granule by
time. Each FOV is placed (:mod:`monitor.matchup.fovs`), the VIIRS pixels inside it summed
(:mod:`monitor.matchup.weighted`), and the sums finished into the product's variables
(:mod:`monitor.matchup.product`): the mean radiance's BT, the pixels' BT spread, their count and the share
of the response they cover. A VIIRS granule is read once and kept while the CrIS granules it covers are
mapped (two per grid at a time: a day's granules come in time order).
"""

from __future__ import annotations

import os
import time
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from monitor.core.bands import BANDS
from monitor.core.constants import N_FOR, N_FOV
from monitor.core.errors import DataError, StopRequested
from monitor.core.result import AssessmentResult
from monitor.instrument.spectral import band_model
from monitor.matchup import fovs as placing
from monitor.matchup.product import Matchup
from monitor.matchup.swaths import BandPixels, GridPixels, band_pixels, grid_pixels, windows
from monitor.matchup.weighted import N_SUMS, NPX, WL, WT, WT2, W, fov_sums
from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import CrisSdrGranule
from monitor.sdr.pairing import CasePlan, GranuleFiles, plan
from monitor.sdr.readers import read_file

KEPT_PER_GRID = 2  # VIIRS granules kept ready per band: a CrIS granule reaches at most two


@dataclass
class MapCost:
    """What a mapping cost, CPU seconds (all threads) by stage: reading per band (``read_s``, the GEO
    counted with the first band of its grid), the rest per band (``map_s``: placing, searching, summing);
    and the bytes read per band (the VIIRS files, the GEO with the first band of its grid)."""

    read_s: dict[str, float] = field(default_factory=dict)
    map_s: dict[str, float] = field(default_factory=dict)
    bytes_read: dict[str, int] = field(default_factory=dict)

    def add(self, table: dict, band: str, value: float) -> None:
        """Add *value* to *band*'s entry of one of the tables.

        Parameters
        ----------
        table : dict
            ``read_s``, ``map_s`` or ``bytes_read``.
        band : str
            The band.
        value : float
            What to add.
        """
        table[band] = table.get(band, 0) + value


def _rchar() -> int:
    """The bytes this process has read through system calls so far (Linux ``rchar``: files, through the
    page cache, and sockets, which a granule read in place comes through); 0 where there is no such count."""
    try:
        with open("/proc/self/io") as io:
            return next((int(line.split()[1]) for line in io if line.startswith("rchar:")), 0)
    except OSError:
        return 0


class _Viirs:
    """The VIIRS granules of each band ready for the mapping, read on first use, the newest few kept."""

    def __init__(self, satellite: str, cost: MapCost) -> None:
        self.satellite = satellite
        self.cost = cost
        self.grids: OrderedDict[str, GridPixels] = OrderedDict()
        self.bands: OrderedDict[tuple[str, str], BandPixels] = OrderedDict()

    def get(self, band: str, v: GranuleFiles) -> BandPixels:
        key = (band, v.key)
        if key in self.bands:
            return self.bands[key]
        t0, read0 = time.process_time(), _rchar()
        detectors = BANDS[band].grid.detectors
        geo_key = str(v.geo)
        if geo_key not in self.grids:
            (geo,) = read_file(v.geo, kinds=("viirs_geo",))
            self.grids[geo_key] = grid_pixels(geo, detectors)
            while len(self.grids) > 2 * KEPT_PER_GRID:
                self.grids.popitem(last=False)
        (sdr,) = read_file(v.sdr, kinds=("viirs_sdr",))
        self.cost.add(self.cost.bytes_read, band, _rchar() - read0)
        pixels = band_pixels(sdr, self.grids[geo_key], band, self.satellite)
        self.bands[key] = pixels
        while len(self.bands) > KEPT_PER_GRID * len(BANDS):
            self.bands.popitem(last=False)
        self.cost.add(self.cost.read_s, band, time.process_time() - t0)
        return pixels


def _cris_bt_k(sdr: CrisSdrGranule, band: str, satellite: str) -> np.ndarray:
    """CrIS convolved with a band's response, as BT (K), shape (nscan, 30, 9); NaN without the spectra."""
    if BANDS[band].cris_band == "SW":
        if sdr.radiance_sw is None or sdr.wavenumber_sw_cm1 is None:
            return np.full(sdr.radiance_lw.shape[:3], np.nan)
        spectra, nu = sdr.radiance_sw, sdr.wavenumber_sw_cm1
    else:
        spectra, nu = sdr.radiance_lw, sdr.wavenumber_cm1
    model = band_model(satellite, band, tuple(float(x) for x in nu))
    return np.asarray(model.bt_from_radiance(model.cris_band_radiance(spectra)), float)


def map_granules(
    paths: Sequence[str | os.PathLike[str]],
    bands: Sequence[str] = tuple(BANDS),
    offsets: AssessmentResult | None = None,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> tuple[Matchup, MapCost]:
    """Map every CrIS FOV of the granules under *paths* onto each VIIRS band.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
        Granule files or directories: CrIS SDR and GEO, each band's VIIRS SDR and its grid's GEO.
    bands : sequence of str, optional
        The VIIRS bands (I5, M13, M15, M16).
    offsets : AssessmentResult, optional
        A day's assessment: each FOV placed on the assessed geolocation with its FOR's fitted response.
        Without it: the operational geolocation and the nominal response.
    should_stop : callable, optional
        Polled between CrIS granules; True ends the mapping with StopRequested.
    progress : callable, optional
        Called with (granules done, granules in all) after each CrIS granule.

    Returns
    -------
    Matchup
        The mapping.
    MapCost
        What it cost, by band.
    """
    bands = tuple(b for b in BANDS if b in bands)
    if not bands:
        raise DataError("no VIIRS band to map onto")
    case = plan(paths, bands)
    if not case.cris_all:
        raise DataError("no CrIS granule (an SDR with its GEO) among " + ", ".join(map(str, paths)))
    return map_plan(case, bands, offsets, should_stop, progress)


def map_plan(
    case: CasePlan,
    bands: Sequence[str],
    offsets: AssessmentResult | None = None,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> tuple[Matchup, MapCost]:
    """Map every CrIS FOV of a paired plan (``cris_all``, or ``cris`` where that is empty) onto each band.

    Parameters
    ----------
    case : CasePlan
        The CrIS granules and, per band, the VIIRS granules (I5's in ``viirs_all``, the others' in
        ``bands``).
    bands : sequence of str
        The VIIRS bands.
    offsets : AssessmentResult, optional
        A day's assessment (as :func:`map_granules`).
    should_stop : callable, optional
        Polled between CrIS granules; True ends the mapping with StopRequested.
    progress : callable, optional
        Called with (granules done, granules in all) after each CrIS granule.

    Returns
    -------
    Matchup
        The mapping.
    MapCost
        What it cost, by band.
    """
    bands = tuple(b for b in BANDS if b in bands)
    cris = case.cris_all or case.cris
    if offsets is not None:
        if offsets.satellite != case.satellite:
            raise DataError(f"the offsets are {offsets.satellite}'s, the granules {case.satellite}'s")
        if len(offsets.fors) != N_FOR:
            raise DataError(f"the offsets hold {len(offsets.fors)} FORs, not {N_FOR}")
    fors = offsets.fors if offsets is not None else None
    resp = placing.responses(fors)
    reach = float(resp.reach_rad.max())
    cost = MapCost()
    viirs = _Viirs(case.satellite, cost)
    nscan = 4 * len(cris)
    shape = (len(bands), nscan, N_FOR, N_FOV)
    values = {name: np.full(shape, np.nan) for name in ("viirs_bt_k", "viirs_bt_std_k", "cris_bt_k")}
    values["viirs_pixels"] = np.zeros(shape)
    values["viirs_valid_fraction"] = np.zeros(shape)
    times = np.zeros((nscan, N_FOR), np.int64)
    lat, lon = np.full((nscan, N_FOR, N_FOV), np.nan), np.full((nscan, N_FOR, N_FOV), np.nan)
    notes = [f"{item}: {why}" for item, why in case.skipped]
    granule_of_scan = np.zeros(nscan, np.int32)
    mapped: list[str] = []
    done_scans = 0
    for gi, g in enumerate(cris):
        if should_stop is not None and should_stop():
            raise StopRequested
        try:
            (geo,) = read_file(g.geo, kinds=("cris_geo",))
            (sdr,) = read_file(g.sdr, kinds=("cris_sdr",))
        except GranuleError as exc:
            notes.append(str(exc))
            continue
        n = geo.lat_rad.shape[0]
        rows = slice(done_scans, done_scans + n)
        granule_of_scan[rows] = len(mapped)
        mapped.append(g.sdr.name)
        placed = placing.place(geo, fors)
        ok = (placed.valid & sdr.good).ravel()
        times[rows] = geo.for_time_us
        lat[rows], lon[rows] = np.degrees(placed.lat_rad), np.degrees(placed.lon_rad)
        table_of = np.broadcast_to(resp.of_for[None, :, None], placed.valid.shape).ravel().copy()
        sat = placed.sat_m.reshape(-1, 3)
        los = np.ascontiguousarray(placed.los.reshape(-1, 3))
        for b, band in enumerate(bands):
            t0, read_before = time.process_time(), cost.read_s.get(band, 0.0)
            cris_bt = _cris_bt_k(sdr, band, case.satellite)
            sums = np.zeros((ok.size, 1, N_SUMS))
            for v in case.cover(g, band):
                try:
                    px = viirs.get(band, v)
                except (GranuleError, ValueError) as exc:
                    notes.append(str(exc))
                    continue
                win = windows(px.grid, placed, reach)
                win[~ok] = 0
                fov_sums(
                    px.grid.pix_m,
                    px.radiance,
                    px.bt_k,
                    px.good,
                    px.grid.detectors,
                    sat,
                    los,
                    win,
                    table_of,
                    resp.tables,
                    resp.reach_rad,
                    sums,
                )
            s = sums[:, 0]
            with np.errstate(invalid="ignore", divide="ignore"):
                mean_l = s[:, WL] / s[:, W]
                mean_t = s[:, WT] / s[:, W]
                spread = np.sqrt(np.maximum(s[:, WT2] / s[:, W] - mean_t**2, 0.0))
            have = s[:, NPX] > 0
            model = band_model(case.satellite, band)
            bt = np.where(have, model.bt_from_radiance(np.where(have, mean_l, np.nan)), np.nan)
            values["viirs_bt_k"][b, rows] = bt.reshape(n, N_FOR, N_FOV)
            values["viirs_bt_std_k"][b, rows] = np.where(have, spread, np.nan).reshape(n, N_FOR, N_FOV)
            values["viirs_pixels"][b, rows] = s[:, NPX].reshape(n, N_FOR, N_FOV)
            frac = np.minimum(s[:, W] / resp.norm_sr[table_of], 1.0)
            values["viirs_valid_fraction"][b, rows] = frac.reshape(n, N_FOR, N_FOV)
            values["cris_bt_k"][b, rows] = np.where(ok.reshape(n, N_FOR, N_FOV), cris_bt, np.nan)
            read = cost.read_s.get(band, 0.0) - read_before  # this band's reading, counted apart
            cost.add(cost.map_s, band, time.process_time() - t0 - read)
        done_scans += n
        if progress is not None:
            progress(gi + 1, len(cris))
    matchup = Matchup(
        satellite=case.satellite,
        bands=bands,
        geolocation="operational" if offsets is None else "assessed",
        response="fitted" if resp.fitted else "nominal",
        time_iet_us=times[:done_scans],
        latitude_deg=lat[:done_scans],
        longitude_deg=lon[:done_scans],
        values={k: v[:, :done_scans] for k, v in values.items()},
        granules=mapped,
        granule_of_scan=granule_of_scan[:done_scans],
        notes=notes,
    )
    return matchup, cost
