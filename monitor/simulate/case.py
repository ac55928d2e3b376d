"""Simulate a case: CrIS SCRIF + GCRSO and VIIRS SVI05 + GITCO granules with an injected LOS error, and
the M-band granules (SVM13, SVM15, SVM16 + GMTCO) where asked for.

Where the case lies on the Earth is a pass of the satellite's own orbit (:data:`PASSES`: tropics by day
on an ascending pass, by night on a descending one, 60-81 deg N or S; optionally nearest a longitude, e.g.
180 deg to cross the antimeridian), or by default an ascending tropical pass at a random longitude.
With terrain, VIIRS GITCO pixels are where each line of sight meets the terrain, with their Height (as
IDPS writes them), CrIS radiances are averaged over the true FOV on the terrain, and GCRSO stays on
the h = 0 ellipsoid with the terrain height only reported (docs/jpss-formats.md 2.3, point 8).

The CrIS FOV sees the scene through the paper's top-hat cone, or through a smooth spatial response, radially
symmetric or elliptical (``SimulationSpec.cris_response``, :mod:`monitor.instrument.footprint`), one for all
FOVs or one per FOV: the CrIS radiance is then the response-weighted mean of the scene out to where the
response ends. An elliptical field turns with the scene mirror, by the FOR's scan angle. The CrIS and the
VIIRS granules share the spacecraft's state, attitude and scene at every instant; the file layouts are data
(:mod:`monitor.simulate.jpss_h5`, :mod:`monitor.simulate.complete`), the scene and terrain modules of their
own.

Four bands (``SimulationSpec.viirs_bands``): every VIIRS band is the band's response applied to the same
top-of-atmosphere spectra CrIS sees (:func:`monitor.simulate.scene.spectra`), at its own grid's geometry
(:data:`monitor.core.bands.GRIDS`: 16 M-band detectors, 3200 aggregated columns, their bow-tie deletion
and column times). So CrIS convolved with any band's response agrees with VIIRS in that band but for the
noise, the response's cut to the CrIS band and a per-band calibration difference one injects
(``viirs_band_bias_k``). The CrIS SW spectra are simulated like the LW ones (VIIRS M13 lies in them).

Clouds with height (``SimulationSpec.cloud_heights``, :mod:`monitor.simulate.clouds`): both instruments'
rays meet the first cloud they pass, its top or its side, and see its temperature there; GEO stays where
the ray meets the terrain (or the ellipsoid), as IDPS writes it. So a high cloud seen by CrIS's rows ahead
(FOVs 7-9, 19 mrad forward) lands forward of where VIIRS puts it, and behind for the rows behind.
``fov_rows_alpha_urad`` turns the true LOS of the rows ahead by half of it in-track and the rows behind by
minus half, which GEO does not know: an error of the EP's FOV positions, ahead minus behind.
"""

from __future__ import annotations

import datetime as dt
import json
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.bands import BANDS, GRIDS, ViirsGrid
from monitor.core.constants import (
    CALIBRATION_CURVATURE_SPAN_K,
    CALIBRATION_REFERENCE_K,
    CRIS_GRANULE_US,
    CRIS_SCAN_US,
    FOV_HALF_ANGLE_RAD,
    N_FOR,
    N_FOV,
    PAPER_GRANULES,
    URAD,
    VIIRS_SCANS,
)
from monitor.core.errors import DataError, StopRequested
from monitor.core.satellites import satellite as satellite_info
from monitor.geometry import frames, wgs84
from monitor.geometry.ep_model import EngineeringPacket, fov5_angles, los_spacecraft
from monitor.instrument.footprint import EllipticalResponse, RadialResponse, Response
from monitor.instrument.spectral import C1, C2, BandModel, band_model, i5_band, planck_radiance
from monitor.sdr import iet
from monitor.sdr.consistency import GRANULE_ID_EPOCH_IET_US
from monitor.sdr.names import format_name
from monitor.sdr.products import PRODUCTS, cris_lw_wavenumbers_cm1, cris_sw_wavenumbers_cm1
from monitor.simulate import CIRRUS_BASE_M, complete
from monitor.simulate import scan_geometry as ins
from monitor.simulate.clouds import CloudHeights
from monitor.simulate.jpss_h5 import ProductData, date_time_attrs, write_file
from monitor.simulate.profiles import load_profile
from monitor.simulate.scene import EDGES, T_ATM_K, Scene, Wind, spectra, transmittance
from monitor.simulate.sun_synchronous import PASSES, CircularOrbit, find_pass

UTC = dt.timezone.utc
DEFAULT_START = dt.datetime(2024, 6, 1, 12, 0, 0, tzinfo=UTC)
CRIS_GRANULE_S = CRIS_GRANULE_US * 1e-6
VIIRS_GRANULE_S = VIIRS_SCANS * ins.VIIRS_SCAN_S
# points over the top-hat cone by the clouds' edges (monitor.simulate.scene.EDGES): a sharp edge needs them
# finer than VIIRS's 375 m pixels, or the CrIS truth itself carries the sampling's error
CONE_SAMPLES = {"soft": 512, "sharp": 4096}
T_BINS_K = np.arange(150.0, 350.0001, 0.05)
# the scene's cloud tops within one standard deviation of its cloud-top field (245 +- 18 K) and its sea
# surface from 55 deg to the equator (289-301 K): where law_m_per_k measures a law's lift
LAW_TOPS_K = np.linspace(227.0, 263.0, 13)
LAW_AIR_K = np.linspace(289.0, 301.0, 5)
BT_SCALE, BT_OFFSET = 0.003, 150.0  # VIIRS BT = DN * scale + offset (every band but M13, float32)
RAD_SCALE, RAD_OFFSET = 0.0002, 0.0
OBPT_U16, OBPT_F32 = 65533, -999.7

DEFAULT_AUX = {
    "cris": [
        "CMNGEO-PARAM-LUT_{p}_20160331000000Z_20170807130000Z_ee00000000000000Z_PS-1-O-CCR-16-2859-v002-LE-PE_all-_all_all-_ops",
        "CrIS-SDR-CC_{p}_20180426000000Z_20180808000000Z_ee00000000000000Z_PS-1-O-CCR-3542-002-LE-PE_all-_all_all-_ops",
    ],
    "viirs": [
        "VIIRS-SDR-GEO-IMG-PARAM-LUT_{p}_20130601000000Z_20130601000000Z_ee00000000000000Z_PS-1-O-CCR-13-1171-JPSS-DPA-009-PE_noaa_all_all-_all",
        "CMNGEO-PARAM-LUT_{p}_20160331000000Z_20170807130000Z_ee00000000000000Z_PS-1-O-CCR-16-2859-v002-LE-PE_all-_all_all-_ops",
    ],
}


@dataclass
class SimulationSpec:
    """What to simulate, every parameter declared once, with its default (``crisgeo simulate``, the
    simulated source and the benchmarks take these). Offsets are the per-FOR turn (urad) that takes the
    GEO LOS onto the true LOS: given, or the *profile*'s (:func:`load_profile`; with engineering packets,
    none: the EPs carry the error)."""

    satellite: str = "j01"
    granules: int = PAPER_GRANULES
    d_alpha_urad: np.ndarray = field(default_factory=lambda: np.empty(0))  # empty: the profile's
    d_beta_urad: np.ndarray = field(default_factory=lambda: np.empty(0))
    seed: int = 0
    start: dt.datetime = DEFAULT_START
    profile: str = "paper"  # paper, random, zero, a file, or "ep" with true_ep and ground_ep
    attitude_arcsec: tuple = (0.6, -0.3, 0.5)
    software_version: str = "I2.3.00.00"
    aux: dict = field(default_factory=lambda: {k: list(v) for k, v in DEFAULT_AUX.items()})
    cris_sdr: bool = True  # False: GEO files only (fast; for fingerprint series)
    viirs_lead_s: float = 10.9  # a VIIRS granule starts this long before the first CrIS granule
    viirs_noise_k: float = 0.3
    cris_noise: float = 0.05  # mW/(m2 sr cm-1) per channel
    true_ep: EngineeringPacket | None = None  # with ground_ep: radiances from true_ep, GEO from ground_ep
    ground_ep: EngineeringPacket | None = None
    terrain: bool = False  # ranges and plateaus of 1-4 km over land (land fraction 0.4 instead of 0.3)
    orbit_pass: str | None = None  # a key of PASSES: the case starts at that pass after *start*
    pass_lon_deg: float | None = None  # with orbit_pass: the pass nearest this longitude (16-day search)
    # CrIS-VIIRS calibration difference, in the BT of every CrIS channel (K): bias + gain (T - 280 K)
    # + nonlinear_k ((T - 280 K) / 30 K)^2; all zero: the two instruments agree
    cris_bias_k: float = 0.0
    cris_gain: float = 0.0  # relative: 0.01 is a 1 % gain difference
    cris_nonlinear_k: float = 0.0
    # every dataset of the real products, also those the monitor never reads (monitor.simulate.complete)
    complete: bool = False
    # HDF5 layout of every dataset, one of LAYOUTS: "contiguous" (uncompressed IDPS files) or "gzip" (one
    # chunk per dataset, as the real GCRSO); None: CrIS gzip, VIIRS contiguous
    layout: str | None = None
    # the CrIS FOV's spatial response: None, the top-hat cone of FOV_DIAMETER_RAD (the paper's); one
    # response for all FOVs, or a tuple of 9 (FOV 1..9)
    cris_response: Response | tuple[Response, ...] | None = None
    # the height of the cloud tops (monitor.simulate.clouds): ground (flat), lapse:G (K/km) or tropical
    cloud_heights: str = "ground"
    # how sharply the clouds' cover ends (monitor.simulate.scene.EDGES): "soft" or "sharp"
    cloud_edges: str = "soft"
    # the true LOS of FOVs 7-9 turned +half this in-track, of FOVs 1-3 -half, unknown to GEO (urad)
    fov_rows_alpha_urad: float = 0.0
    # the clouds move this fast along the track (m/s, + in the direction of flight) between the two
    # instruments' views; the land stays
    wind_in_track_m_s: float = 0.0
    # the emissivity of the clouds above CIRRUS_BASE_M (thin cirrus): below 1 the ground shows through
    cloud_emissivity: float = 1.0
    # the VIIRS bands written (monitor.core.bands.BANDS); I5 is the assessment's
    viirs_bands: tuple[str, ...] = ("I5",)
    # a VIIRS calibration difference per band: K added to VIIRS's BT in that band (CrIS minus VIIRS reads
    # minus it)
    viirs_band_bias_k: dict = field(default_factory=dict)
    # the CrIS short-wave noise per channel, mW/(m2 sr cm-1)
    cris_noise_sw: float = 0.004

    def compressed(self, instrument: str) -> bool:
        """Whether the datasets of *instrument* (CrIS, VIIRS) are written gzip-compressed.

        Parameters
        ----------
        instrument : str
            ``cris`` or ``viirs``.

        Returns
        -------
        bool
            Whether its datasets are gzip-compressed.
        """
        return self.layout == "gzip" if self.layout is not None else instrument == "CrIS"

    @property
    def calibrated(self) -> bool:
        """Whether CrIS and VIIRS agree radiometrically (no calibration difference).

        Returns
        -------
        bool
            True with no calibration difference.
        """
        return self.cris_bias_k == 0.0 and self.cris_gain == 0.0 and self.cris_nonlinear_k == 0.0

    def cris_bt_k(self, bt_k: np.ndarray) -> np.ndarray:
        """The BT CrIS reports for a scene of true brightness temperature *bt_k* (K).

        Parameters
        ----------
        bt_k : numpy.ndarray
            True brightness temperature, K.

        Returns
        -------
        numpy.ndarray
            K.
        """
        x = bt_k - CALIBRATION_REFERENCE_K
        return (
            bt_k
            + self.cris_bias_k
            + self.cris_gain * x
            + self.cris_nonlinear_k * (x / CALIBRATION_CURVATURE_SPAN_K) ** 2
        )

    def __post_init__(self) -> None:
        if self.d_alpha_urad.size == 0 or self.d_beta_urad.size == 0:
            by_ep = self.true_ep is not None  # the EPs carry the error
            d_alpha, d_beta = (
                (np.zeros(N_FOR), np.zeros(N_FOR)) if by_ep else load_profile(self.profile, self.seed)
            )
            self.d_alpha_urad, self.d_beta_urad = np.asarray(d_alpha, float), np.asarray(d_beta, float)
        if self.orbit_pass is not None and self.orbit_pass not in PASSES:
            raise DataError(f"orbit pass {self.orbit_pass!r} is not one of {', '.join(PASSES)}")
        if isinstance(self.cris_response, tuple) and len(self.cris_response) != N_FOV:
            raise DataError(f"a response per FOV needs {N_FOV}, not {len(self.cris_response)}")
        CloudHeights.parse(self.cloud_heights)  # a law it does not know is a DataError now, not mid-case
        if self.cloud_edges not in EDGES:
            raise DataError(f"cloud edges {self.cloud_edges!r}: not one of {', '.join(EDGES)}")
        unknown = [b for b in (*self.viirs_bands, *self.viirs_band_bias_k) if b not in BANDS]
        if unknown or not self.viirs_bands:
            raise DataError(
                f"VIIRS band(s) {', '.join(unknown) or '(none)'}: each must be one of {', '.join(BANDS)}"
            )
        if not all(
            math.isfinite(float(v)) and abs(float(v)) <= 10.0 for v in self.viirs_band_bias_k.values()
        ):
            raise DataError(f"VIIRS band bias {self.viirs_band_bias_k}: each must be a finite K within +-10")
        if not 0.0 < self.cloud_emissivity <= 1.0:
            raise DataError(f"cloud emissivity {self.cloud_emissivity!r}: not in (0, 1]")
        if not math.isfinite(self.wind_in_track_m_s):
            raise DataError(f"wind {self.wind_in_track_m_s!r} m/s: not a number")
        if self.pass_lon_deg is not None and self.orbit_pass is None:
            raise DataError("a pass longitude needs an orbit pass")
        if (self.true_ep is None) != (self.ground_ep is None):
            raise DataError("a simulation in EP terms needs both the true EP and the ground-processing EP")
        if self.true_ep is not None and self.ground_ep is not None:
            for ep in (self.true_ep, self.ground_ep):
                if ep.satellite != self.satellite:
                    raise DataError(
                        f"EP {ep.version} is for {ep.satellite}, the simulation for {self.satellite}"
                    )
            self.d_alpha_urad, self.d_beta_urad = ep_offsets_urad(self.true_ep, self.ground_ep)


def ep_offsets_urad(
    true_ep: EngineeringPacket, ground_ep: EngineeringPacket
) -> tuple[np.ndarray, np.ndarray]:
    """Per-FOR (d_alpha, d_beta) (urad) of FOV 5 from the ground-processing LOS to the true one.

    Parameters
    ----------
    true_ep, ground_ep : EngineeringPacket
        The EP the radiances are made with, and the ground processing's.

    Returns
    -------
    d_alpha_urad, d_beta_urad : numpy.ndarray
        Shape (30,).
    """
    a_true, b_true = fov5_angles(true_ep)
    a_geo, b_geo = fov5_angles(ground_ep)
    return (a_true - a_geo) / URAD, (b_true - b_geo) / URAD


def _unix_s(when: dt.datetime) -> float:
    return when.timestamp()


def _iet_us(unix_s: ArrayLike) -> np.ndarray:
    return iet.unix_us_to_iet(np.round(np.asarray(unix_s) * 1e6).astype(np.int64))


def _granule_id(platform: str, nominal_start_iet_us: int) -> str:
    return f"{platform.upper()}{(nominal_start_iet_us - GRANULE_ID_EPOCH_IET_US) // 100000:012d}"


def _utc(unix_s: float) -> dt.datetime:
    """Timezone-aware UTC datetime of UTC seconds since 1970."""
    return dt.datetime.fromtimestamp(unix_s, UTC)


Point = tuple[np.ndarray, np.ndarray, np.ndarray]  # geodetic (lat_rad, lon_rad, h_m)
TOP_HAT_CONE = RadialResponse((0.0, FOV_HALF_ANGLE_RAD), (1.0, 1.0))


def _sunflower_disk(n: int, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """*n* (even) points evenly spread over a disk: a sunflower of n/2 points and its point reflection.

    A sunflower alone is off-centre by ~2e-3 of its radius (17 urad for the CrIS cone with 256 points),
    which biased the simulated CrIS truth cross-track; the reflected pairs put the centroid at zero.
    """
    k = np.arange(n // 2) + 0.5
    r = radius * np.sqrt(k / (n // 2))
    phi = k * np.pi * (3.0 - np.sqrt(5.0))
    x, y = r * np.cos(phi), r * np.sin(phi)
    return np.concatenate([x, -x]), np.concatenate([y, -y])


def _band_table(band: BandModel, nu: np.ndarray, planck_table: np.ndarray) -> np.ndarray:
    """VIIRS band radiance of a pixel whose emitting temperature is each of T_BINS_K, seen through the
    simulator's atmosphere (:func:`monitor.simulate.scene.transmittance`, emitting at T_ATM_K)."""
    tau = transmittance(nu)
    return (tau * planck_table + (1 - tau) * planck_radiance(nu, T_ATM_K)) @ band.weights


def law_m_per_k(satellite: str, clouds: str) -> float | None:
    """The lift (m per K) a case's cloud law *clouds* implies in the units the assessment learns it
    (``parallax_m_per_k``: height per K of VIIRS I5 BT below the clear sky), None for clouds on the ground.

    A top's height follows its emitting temperature's cooling below the air (:mod:`~.clouds`), while the
    lift reads the band BT's: through the simulator's atmosphere the window shrinks a BT contrast to
    0.79-0.84 of the temperatures' (colder tops more), so a lapse law of G K/km implies about 1230 / G
    m/K, not 1000 / G. The slope through the origin, by least squares, of the height over the BT cooling
    over the scene's tops (:data:`LAW_TOPS_K`) above its sea surface (:data:`LAW_AIR_K`).

    Parameters
    ----------
    satellite : str
        The satellite's short name (its I5 band).
    clouds : str
        The law (``ground``, ``lapse:G``, ``tropical``).

    Returns
    -------
    float or None
        m per K of band BT; None for clouds on the ground.
    """
    law = CloudHeights.parse(clouds)
    if law.flat:
        return None
    band, nu = i5_band(satellite), cris_lw_wavenumbers_cm1()
    table = _band_table(band, nu, planck_radiance(nu[None, :], T_BINS_K[:, None]))
    top_k, air_k = np.meshgrid(LAW_TOPS_K, LAW_AIR_K)
    height_m = law.top_height_m(top_k, air_k).astype(np.float64)
    cooling_k = band.bt_from_radiance(np.interp(air_k, T_BINS_K, table)) - band.bt_from_radiance(
        np.interp(top_k, T_BINS_K, table)
    )
    return round(float(np.sum(height_m * cooling_k) / np.sum(cooling_k**2)), 1)


class Simulator:
    """Builds the orbit, attitude and scene of a case and writes its granules.

    Parameters
    ----------
    spec : SimulationSpec
        The case.
    """

    def __init__(self, spec: SimulationSpec):
        self.spec = spec
        sat = satellite_info(spec.satellite)
        rng = np.random.default_rng(spec.seed)
        night = False
        if spec.orbit_pass is None:
            self.t0 = _unix_s(spec.start)
            self.orbit = CircularOrbit.through(
                self.t0,
                lon0_deg=rng.uniform(-180, 180),
                u0_deg=-14.0 + rng.uniform(-3, 3),
                altitude_m=sat.altitude_m,
                inclination_deg=sat.inclination_deg,
            )
        else:
            lat, ascending = PASSES[spec.orbit_pass]
            self.t0 = round(find_pass(sat, _unix_s(spec.start), lat, ascending, spec.pass_lon_deg), 1)
            self.orbit = CircularOrbit.of(sat, self.t0)
            night = not ascending  # the descending node of a 13:30 orbit is at 01:30 local time
        self.scene = Scene(
            spec.seed,
            land_fraction=0.4 if spec.terrain else 0.3,
            terrain=spec.terrain,
            night=night,
            clouds=CloudHeights.parse(spec.cloud_heights),
            edges=spec.cloud_edges,
            wind=self._wind(),
        )
        self.band = i5_band(spec.satellite)
        self.nu = cris_lw_wavenumbers_cm1()
        self.planck_table = planck_radiance(self.nu[None, :], T_BINS_K[:, None])
        self.band_table = _band_table(self.band, self.nu, self.planck_table)
        self.nu_sw = cris_sw_wavenumbers_cm1()
        self.planck_table_sw = planck_radiance(self.nu_sw[None, :], T_BINS_K[:, None])
        self.band_tables = {
            b: _band_table(
                band_model(spec.satellite, b),
                self.nu_sw if BANDS[b].cris_band == "SW" else self.nu,
                self.planck_table_sw if BANDS[b].cris_band == "SW" else self.planck_table,
            )
            for b in spec.viirs_bands
        }
        self.rng = rng
        if spec.true_ep is not None and spec.ground_ep is not None:
            self.los_true, self.los_geo = los_spacecraft(spec.true_ep), los_spacecraft(spec.ground_ep)
        else:
            self.los_true = ins.cris_los_sbf()
            self.los_geo = ins.cris_los_sbf(-spec.d_alpha_urad * URAD, -spec.d_beta_urad * URAD)
        if spec.fov_rows_alpha_urad:
            rows = np.zeros(N_FOV)
            rows[6:9], rows[0:3] = 0.5, -0.5  # FOVs 7-9 ahead, 1-3 behind
            self.los_true = ins.turned(self.los_true, rows * spec.fov_rows_alpha_urad * URAD, 0.0)

    def _wind(self) -> Wind:
        """The clouds' :class:`Wind` along the track: about the orbit's normal at the case's start."""
        r, v = self.orbit.state_ecef(self.t0)
        axis = frames.unit(np.cross(r, v))
        return Wind((float(axis[0]), float(axis[1]), float(axis[2])), self.spec.wind_in_track_m_s, self.t0)

    def attitude_rad(self, unix_s: ArrayLike) -> np.ndarray:
        """Spacecraft roll, pitch, yaw (rad): small constants plus a slow drift.

        Parameters
        ----------
        unix_s : array_like
            UTC seconds since 1970.

        Returns
        -------
        numpy.ndarray
            Roll, pitch, yaw, rad, shape t + (3,).
        """
        t = np.asarray(unix_s, float) - self.t0
        base = np.asarray(self.spec.attitude_arcsec, float)
        drift = 0.1 * np.stack([np.sin(t / 600.0), np.cos(t / 900.0), np.sin(t / 700.0)], -1)
        return (base + drift) * frames.ARCSEC_RAD

    def state(self, unix_s: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Satellite position (m) and velocity (m/s) in ECEF and the SBF-to-ECEF matrix at unix times.

        Parameters
        ----------
        unix_s : array_like
            UTC seconds since 1970.

        Returns
        -------
        position_m, velocity_m_s : numpy.ndarray
            ECEF, shape t + (3,).
        sbf_to_ecef : numpy.ndarray
            Shape t + (3, 3).
        """
        r, v = self.orbit.state_ecef(unix_s)
        return r, v, frames.sbf_to_ecef(r, v, self.attitude_rad(unix_s))

    # ------------------------------------------------------------------ CrIS
    def cris_granule(self, k: int, out: Path) -> list[str]:
        """Write CrIS granule *k* (SDR and GEO files) into *out*; the names of the files written.

        Parameters
        ----------
        k : int
            The granule, 0-based.
        out : Path
            The case's directory.

        Returns
        -------
        list of str
            The files written.
        """
        spec = self.spec
        g0 = self.t0 + k * CRIS_GRANULE_S
        scan_start = g0 + np.arange(4) * CRIS_SCAN_US * 1e-6
        for_unix = scan_start[:, None] + np.arange(ins.N_FOR) * ins.CRIS_FOR_DT_US * 1e-6
        r, v, m = self.state(for_unix)  # (4, 30, ...)
        true_ecef = np.einsum("skij,kfj->skfi", m, self.los_true)
        geo_ecef = np.einsum("skij,kfj->skfi", m, self.los_geo)
        sat = np.broadcast_to(r[:, :, None, :], geo_ecef.shape)
        t = wgs84.intersect_ellipsoid(sat, geo_ecef)
        ground = sat + t[..., None] * geo_ecef
        lat, lon, _ = wgs84.ecef_to_geodetic(ground)
        zen, az, rng_m = wgs84.zenith_azimuth(ground, sat)
        height = self.scene.height_m(lat, lon)  # reported only: GCRSO points are on the ellipsoid
        if spec.cris_sdr:
            radiance, sw = self._cris_spectra(sat, true_ecef, m[..., :, 0], for_unix)
            radiance += self.rng.normal(0.0, spec.cris_noise, radiance.shape)
            # the SW noise from a generator of its own: the LW and VIIRS draws stay those of an LW-only case
            sw += np.random.default_rng([spec.seed, 13, k]).normal(0.0, spec.cris_noise_sw, sw.shape)

        for_iet = _iet_us(for_unix)
        start_iet = for_iet[:, 0]
        mid_iet = start_iet + ins.CRIS_MID_OFFSET_US
        r_mid, v_mid = self.orbit.state_ecef(iet.iet_to_unix_us(mid_iet) * 1e-6)
        att_mid = self.attitude_rad(iet.iet_to_unix_us(mid_iet) * 1e-6) / frames.ARCSEC_RAD
        begin, end = for_unix[0, 0], for_unix[-1, -1]
        gid = _granule_id(spec.satellite, int(start_iet[0]) - 4_400_000)
        attrs = self._granule_attrs(
            begin,
            end,
            int(for_iet[0, 0]),
            int(for_iet[-1, -1]),
            gid,
            4,
            v[0, 0],
            lat,
            lon,
            spec.aux["cris"],
        )
        geo = {
            "FORTime": for_iet,
            "StartTime": start_iet,
            "MidTime": mid_iet,
            "Latitude": np.degrees(lat).astype(np.float32),
            "Longitude": np.degrees(lon).astype(np.float32),
            "Height": height.astype(np.float32),
            "SatelliteRange": rng_m.astype(np.float32),
            "SatelliteZenithAngle": np.degrees(zen).astype(np.float32),
            "SatelliteAzimuthAngle": np.degrees(az).astype(np.float32),
            "SolarZenithAngle": np.full(lat.shape, -999.3, np.float32),
            "SolarAzimuthAngle": np.full(lat.shape, -999.3, np.float32),
            **(self._cris_solar(lat, lon, for_unix) if spec.complete else {}),
            "SCPosition": r_mid.astype(np.float32),
            "SCVelocity": v_mid.astype(np.float32),
            "SCAttitude": att_mid.astype(np.float32),
            "QF1_CRISSDRGEO": np.zeros(4, np.uint8),
            "PadByte1": np.zeros(4, np.uint8),
        }
        products = [("GCRSO", geo, "GEO")]
        if spec.cris_sdr:
            t_mean = self.band.bt_from_radiance(self.band.band_radiance(radiance))
            mw = planck_radiance(1208.75 + 0.625 * np.arange(869), t_mean[..., None]).astype(np.float32)
            sw = sw.astype(np.float32)
            products.append(
                (
                    "SCRIF",
                    {
                        "ES_RealLW": radiance.astype(np.float32),
                        "ES_RealMW": mw,
                        "ES_RealSW": sw,
                        "QF1_SCAN_CRISSDR": np.zeros(4, np.uint8),
                        "QF3_CRISSDR": np.zeros((4, 30, 9, 3), np.uint8),
                        **(
                            complete.cris_sdr_extra({"LW": radiance, "MW": mw, "SW": sw}, self.rng)
                            if spec.complete
                            else {}
                        ),
                    },
                    "SDR",
                )
            )
        names = []
        for prefix, data, tag in products:
            product = PRODUCTS[prefix]
            created = _utc(end + 1800 + (7 if prefix == "GCRSO" else 0))
            a = dict(attrs, N_Reference_ID=f"{product.collection}:{gid}:A1")
            name = format_name(
                [prefix], spec.satellite, _utc(begin), _utc(end), attrs["N_Beginning_Orbit_Number"], created
            )
            write_file(
                out / name,
                spec.satellite,
                created,
                [ProductData(product, "CrIS", tag, data, [a], {}, compress=spec.compressed("CrIS"))],
            )
            names.append(name)
        return names

    @staticmethod
    def _cris_solar(lat_rad: np.ndarray, lon_rad: np.ndarray, for_unix: np.ndarray) -> dict:
        """GCRSO's solar angles (deg) at each FOV (fill in the reduced files: the monitor never reads
        them)."""
        sun = complete.sun_direction_ecef(for_unix)[..., None, :]
        zen, az, _ = complete.view_angles(lat_rad, lon_rad, 0.0, sun, direction=True)
        return {"SolarZenithAngle": zen.astype(np.float32), "SolarAzimuthAngle": az.astype(np.float32)}

    def surface(self, origin: np.ndarray, los: np.ndarray) -> Point:
        """Where each ray meets the scene: geodetic (lat_rad, lon_rad, h_m), on the terrain if there is
        one.

        Parameters
        ----------
        origin : numpy.ndarray
            Ray origins, ECEF, m.
        los : numpy.ndarray
            Unit ray directions, ECEF.

        Returns
        -------
        lat_rad, lon_rad, h_m : numpy.ndarray
            Geodetic.
        """
        if not self.spec.terrain:
            pts = origin + wgs84.intersect_ellipsoid(origin, los)[..., None] * los
            lat, lon = wgs84.surface_to_geodetic(pts)
            return lat, lon, np.zeros(lat.shape)
        return self.scene.intersect(origin, los, clouds=False)[1:]

    def met(self, origin: np.ndarray, los: np.ndarray, unix_s: ArrayLike, ground: Point) -> Point:
        """Where each ray at *unix_s* meets the first cloud or terrain, the clouds where the wind has them
        then: geodetic (lat_rad, lon_rad, h_m); with clouds on the ground, *ground* (:meth:`surface`).

        Parameters
        ----------
        origin : numpy.ndarray
            Ray origins, ECEF, m.
        los : numpy.ndarray
            Unit ray directions, ECEF.
        unix_s : array_like
            UTC seconds since 1970.
        ground : tuple of numpy.ndarray
            Where the rays meet the ground (:meth:`surface`).

        Returns
        -------
        lat_rad, lon_rad, h_m : numpy.ndarray
            Geodetic.
        """
        if self.scene.clouds.flat:
            return ground
        return self.scene.intersect(origin, los, unix_s=unix_s)[1:]

    def seen(
        self, origin: np.ndarray, los: np.ndarray, unix_s: ArrayLike, ground: Point | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The temperatures (K) each ray at *unix_s* sees and the weights of their radiances, (n, ...) both:
        what it meets (:meth:`met`; the scene's temperature is a function of its latitude, longitude and
        the terrain's height there), and where that is a thin cloud (above :data:`CIRRUS_BASE_M`, of
        emissivity below 1) also the ground behind it (:meth:`surface`, or *ground* if already known).
        Radiances add with these weights; temperatures must not (the radiance is not linear in them).

        Parameters
        ----------
        origin : numpy.ndarray
            Ray origins, ECEF, m.
        los : numpy.ndarray
            Unit ray directions, ECEF.
        unix_s : array_like
            UTC seconds since 1970.
        ground : tuple of numpy.ndarray, optional
            Where the rays meet the ground.

        Returns
        -------
        temperature_k, weight : numpy.ndarray
            Shape (n, ...) both.
        """
        ground = ground or self.surface(origin, los)
        lat, lon, hit_m = self.met(origin, los, unix_s, ground)
        terrain_m = hit_m if self.scene.clouds.flat else self.scene.height_m(lat, lon)
        temp = self.scene.temperature_k(lat, lon, terrain_m, unix_s=unix_s)
        if self.spec.cloud_emissivity == 1.0:
            return temp[None], np.ones((1,) + temp.shape)
        thin = np.where(np.nan_to_num(hit_m) > CIRRUS_BASE_M, self.spec.cloud_emissivity, 1.0)
        behind = self.scene.temperature_k(*ground, cloudy=False)
        return np.stack([temp, behind]), np.stack([thin, 1.0 - thin])

    @property
    def _fov_disk(self) -> tuple[np.ndarray, np.ndarray]:
        """The FOV's sample points (x, y), tangents of the angle from the LOS: CONE_SAMPLES points over the
        top-hat cone, as densely out to the reach of a spatial response."""
        reach = max(self._responses, key=lambda r: r.reach_rad).reach_rad
        n = 2 * round(CONE_SAMPLES[self.spec.cloud_edges] * (reach / FOV_HALF_ANGLE_RAD) ** 2 / 2)
        return _sunflower_disk(n, np.tan(reach))

    @property
    def _responses(self) -> tuple[Response, ...]:
        """The spatial response of each FOV 1..9 (the top-hat cone's where none is given)."""
        r = self.spec.cris_response
        if r is None:
            return (TOP_HAT_CONE,) * N_FOV
        return r if isinstance(r, tuple) else (r,) * N_FOV

    def _fov_weights(self, psi_rad: np.ndarray) -> np.ndarray:
        """(..., 30, 9, samples): each FOV's response at every sample point of :attr:`_fov_disk` (the top-hat
        cone: 1 at each), *psi_rad* (..., 30, 9) the angle from the disk's x axis to the in-track direction,
        the field turned by the FOR's scan angle as the scene mirror turns it."""
        x, y = self._fov_disk
        if self.spec.cris_response is None:
            return np.ones(psi_rad.shape + x.shape)
        rho = np.hypot(x, y)
        to_angle = np.divide(np.arctan(rho), rho, out=np.ones_like(rho), where=rho > 0)
        c, s = np.cos(psi_rad)[..., None], np.sin(psi_rad)[..., None]
        along, across = (c * x + s * y) * to_angle, (-s * x + c * y) * to_angle
        turns = ins.cris_scan_angles_rad()
        out = np.empty(along.shape)
        for k, turn in enumerate(turns):
            for f, resp in enumerate(self._responses):
                out[..., k, f, :] = resp.at(along[..., k, f, :], across[..., k, f, :], turn)
        return out

    def _cris_spectra(
        self, sat: np.ndarray, los_ecef: np.ndarray, in_track_ecef: np.ndarray, for_unix: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """LW spectra (nscan, 30, 9, 717) and SW spectra (nscan, 30, 9, 637) averaged over each true FOV on
        the scene (the top-hat cone, or weighted by the spatial response out to its reach) as it is at each
        FOR's time *for_unix* (nscan, 30), not the VIIRS grid; *in_track_ecef* (nscan, 30, 3), the SBF x
        axis, orients an elliptical response."""
        x, y = self._fov_disk
        n = len(x)
        helper = np.where(np.abs(los_ecef[..., 2:3]) < 0.9, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
        e1 = frames.unit(np.cross(los_ecef, helper))
        e2 = np.cross(los_ecef, e1)
        dirs = frames.unit(
            los_ecef[..., None, :] + x[:, None] * e1[..., None, :] + y[:, None] * e2[..., None, :]
        )
        ahead = np.broadcast_to(in_track_ecef[:, :, None, :], los_ecef.shape)
        weights = self._fov_weights(np.arctan2(np.sum(ahead * e2, -1), np.sum(ahead * e1, -1)))
        origin = np.broadcast_to(sat[..., None, :], dirs.shape)
        temps, parts = self.seen(origin, dirs, for_unix[:, :, None, None])
        w = weights.reshape(-1, n)
        nfov = w.shape[0]
        hist = np.zeros(nfov * len(T_BINS_K))
        rows = np.repeat(np.arange(nfov), n) * len(T_BINS_K)
        for temp, part in zip(temps, parts, strict=True):  # the cloud, and the ground behind a thin one
            pos = (np.clip(temp.reshape(-1, n), T_BINS_K[0], T_BINS_K[-1] - 1e-6) - T_BINS_K[0]) / (
                T_BINS_K[1] - T_BINS_K[0]
            )
            b0 = np.floor(pos).astype(np.int64)
            w1 = pos - b0
            wp = w * np.broadcast_to(part, temp.shape).reshape(-1, n)
            hist += np.bincount(rows + b0.ravel(), (wp * (1 - w1)).ravel(), hist.size)
            hist += np.bincount(rows + b0.ravel() + 1, (wp * w1).ravel(), hist.size)
        out = []
        for nu, table in ((self.nu, self.planck_table), (self.nu_sw, self.planck_table_sw)):
            mean_planck = hist.reshape(nfov, -1) @ table / w.sum(axis=1, keepdims=True)
            radiance = spectra(nu, mean_planck)
            if not self.spec.calibrated:  # each channel's BT as CrIS would report it
                bt_k = C2 * nu / np.log1p(C1 * nu**3 / radiance)
                radiance = planck_radiance(nu, self.spec.cris_bt_k(bt_k))
            out.append(radiance.reshape(sat.shape[:-1] + (len(nu),)))
        return out[0], out[1]

    # ------------------------------------------------------------------ VIIRS
    def viirs_granule(
        self,
        g0: float,
        out: Path,
        scans_per_chunk: int = 6,
        should_stop: Callable[[], bool] | None = None,
        grid: ViirsGrid = GRIDS["I"],
    ) -> list[str]:
        """Write the VIIRS granule of one grid starting at unix time *g0* into *out*: its GEO file and the SDR
        file of each band of :attr:`SimulationSpec.viirs_bands` on the grid, a few scans at a time
        (*should_stop* polled between them); the names of the files written.

        Parameters
        ----------
        g0 : float
            The granule's start, Unix s.
        out : Path
            The case's directory.
        scans_per_chunk : int, optional
            Scans simulated at a time.
        should_stop : callable, optional
            Polled between chunks.
        grid : ViirsGrid, optional
            The I-band grid (I5, the default) or the M-band grid (M13, M15, M16).

        Returns
        -------
        list of str
            The files written.
        """
        spec = self.spec
        bands = [b for b in spec.viirs_bands if BANDS[b].resolution == grid.resolution]
        if not bands:
            return []
        theta, col_dt = ins.viirs_column_geometry(grid)
        a_det = ins.viirs_detector_angles_rad(grid)
        local = frames.unit(np.stack([np.tan(a_det), np.zeros_like(a_det), np.ones_like(a_det)], -1))
        los_sbf = np.einsum("cij,dj->dci", frames.rot_x(-theta), local)  # (detectors, columns, 3)
        deleted = ins.viirs_bowtie_deleted(grid)
        nrow, ncol = VIIRS_SCANS * grid.detectors, grid.columns
        lat_out = np.empty((nrow, ncol), np.float32)
        lon_out = np.empty_like(lat_out)
        h_out = np.empty_like(lat_out)
        bt_out = {b: np.empty((nrow, ncol), np.float64) for b in bands}
        scan_start = g0 + np.arange(VIIRS_SCANS) * ins.VIIRS_SCAN_S
        # the I5 noise comes from the case's generator, as in a one-band case; each other band has its own
        rngs = {
            b: self.rng if b == "I5" else np.random.default_rng([spec.seed, list(BANDS).index(b), round(g0)])
            for b in bands
        }
        for s0 in range(0, VIIRS_SCANS, scans_per_chunk):
            if should_stop is not None and should_stop():
                raise StopRequested
            ss = slice(s0, s0 + scans_per_chunk)
            tt = scan_start[ss, None] + col_dt[None, :]
            r, _, m = self.state(tt)  # (n, columns, 3), (n, columns, 3, 3)
            los = np.einsum("scij,dcj->sdci", m, los_sbf)
            origin = np.broadcast_to(r[:, None], los.shape)
            lat, lon, h = self.surface(origin, los)
            temps, parts = self.seen(origin, los, tt[:, None, :], (lat, lon, h))
            rows = slice(s0 * grid.detectors, (s0 + lat.shape[0]) * grid.detectors)
            for b in bands:
                model, table = band_model(spec.satellite, b), self.band_tables[b]
                lrad = sum(p * np.interp(t, T_BINS_K, table) for t, p in zip(temps, parts, strict=True))
                bt = model.bt_from_radiance(lrad) + rngs[b].normal(0, spec.viirs_noise_k, lat.shape)
                bt_out[b][rows] = (bt + float(spec.viirs_band_bias_k.get(b, 0.0))).reshape(-1, ncol)
            lat_out[rows] = np.degrees(lat).reshape(-1, ncol)
            lon_out[rows] = np.degrees(lon).reshape(-1, ncol)
            h_out[rows] = h.reshape(-1, ncol)
        mask = np.tile(deleted, (VIIRS_SCANS, 1))
        lat_out[mask] = OBPT_F32
        lon_out[mask] = OBPT_F32
        h_out[mask] = OBPT_F32

        start_iet = _iet_us(scan_start)
        mid_iet = start_iet + int(ins.VIIRS_EARTH_VIEW_S / 2 * 1e6)
        mid_unix = iet.iet_to_unix_us(mid_iet) * 1e-6
        r_mid, v_mid = self.orbit.state_ecef(mid_unix)
        att_mid = self.attitude_rad(mid_unix) / frames.ARCSEC_RAD
        end = g0 + VIIRS_GRANULE_S
        gid = _granule_id(spec.satellite, int(start_iet[0]))
        valid = ~mask
        geo_prefix = grid.geo_prefixes[0]
        attrs = self._granule_attrs(
            g0,
            end,
            int(start_iet[0]),
            int(_iet_us(end)),
            gid,
            VIIRS_SCANS,
            v_mid[0],
            np.radians(lat_out[valid][::97]),
            np.radians(lon_out[valid][::97]),
            spec.aux["viirs"],
        )
        per_scan = {
            "StartTime": start_iet,
            "MidTime": mid_iet,
            "SCPosition": r_mid.astype(np.float32),
            "SCVelocity": v_mid.astype(np.float32),
            "SCAttitude": att_mid.astype(np.float32),
            "QF1_SCAN_VIIRSSDRGEO": np.zeros(VIIRS_SCANS, np.uint8),
            "NumberOfScans": np.array([VIIRS_SCANS], np.int32),
        }
        geo = {
            "Latitude": lat_out,
            "Longitude": lon_out,
            "Height": h_out,
            "QF2_VIIRSSDRGEO": np.zeros(lat_out.shape, np.uint8),
            **per_scan,
        }
        if spec.complete:
            geo |= complete.viirs_geo_extra(lat_out, lon_out, h_out, r_mid, scan_start, grid.detectors)
        files = [(geo_prefix, geo, "GEO", "N/A")]
        for b in bands:
            files.append((BANDS[b].sdr_prefix, self._viirs_sdr_data(b, bt_out[b], mask), "SDR", b))
        names = []
        for prefix, data, tag, band_id in files:
            product = PRODUCTS[prefix]
            created = _utc(end + 1700 + (3 if tag == "GEO" else 0))
            a = dict(attrs, N_Reference_ID=f"{product.collection}:{gid}:A1", Band_ID=band_id)
            name = format_name(
                [prefix], spec.satellite, _utc(g0), _utc(end), attrs["N_Beginning_Orbit_Number"], created
            )
            write_file(
                out / name,
                spec.satellite,
                created,
                [ProductData(product, "VIIRS", tag, data, [a], {}, compress=spec.compressed("VIIRS"))],
            )
            names.append(name)
        return names

    def _viirs_sdr_data(self, band: str, bt_k: np.ndarray, deleted: np.ndarray) -> dict:
        """A band's SDR datasets from its pixels' BT (K): BT and radiance as IDPS stores them (uint16 and
        factors; float32 for M13), bow-tie deleted pixels filled (OBPT)."""
        b, model = BANDS[band], band_model(self.spec.satellite, band)
        cwv = float(np.sum(model.weights * model.wavenumber_cm1))
        # W/(m2 sr um) from mW/(m2 sr cm-1): L_lambda = L_nu * nu^2 / 1e4 / 1e3
        lam = model.radiance_from_bt(bt_k) * cwv**2 * 1e-7
        if b.bt_scaled:
            bt = np.clip(np.round((bt_k - BT_OFFSET) / BT_SCALE), 0, 65527).astype(np.uint16)
            rad = np.clip(np.round((lam - RAD_OFFSET) / RAD_SCALE), 0, 65527).astype(np.uint16)
            bt[deleted], rad[deleted] = OBPT_U16, OBPT_U16
            values = {
                "BrightnessTemperature": bt,
                "BrightnessTemperatureFactors": np.array([BT_SCALE, BT_OFFSET], np.float32),
                "Radiance": rad,
                "RadianceFactors": np.array([RAD_SCALE, RAD_OFFSET], np.float32),
            }
        else:
            bt32, rad32 = bt_k.astype(np.float32), np.nan_to_num(lam, nan=OBPT_F32).astype(np.float32)
            bt32[deleted], rad32[deleted] = OBPT_F32, OBPT_F32
            values = {"BrightnessTemperature": bt32, "Radiance": rad32}
        data = {
            **values,
            b.quality_dataset: np.zeros(bt_k.shape, np.uint8),
            "QF2_SCAN_SDR": np.zeros(VIIRS_SCANS, np.uint8),
            "NumberOfScans": np.array([VIIRS_SCANS], np.int32),
        }
        if self.spec.complete:
            data |= complete.viirs_sdr_extra(VIIRS_SCANS, b.grid.detectors)
        return data

    def _granule_attrs(
        self,
        begin: float,
        end: float,
        begin_iet: int,
        end_iet: int,
        gid: str,
        nscan: int,
        v0: np.ndarray,
        lat: np.ndarray,
        lon: np.ndarray,
        aux: Sequence[str],
    ) -> dict:
        p = self.spec.satellite
        lat_d, lon_d = np.degrees(lat), np.degrees(lon)
        return {
            "Ascending/Descending_Indicator": 0 if v0[2] > 0 else 1,
            **date_time_attrs("Beginning", _utc(begin)),
            **date_time_attrs("Ending", _utc(end)),
            "East_Bounding_Coordinate": float(np.nanmax(lon_d)),
            "West_Bounding_Coordinate": float(np.nanmin(lon_d)),
            "North_Bounding_Coordinate": float(np.nanmax(lat_d)),
            "South_Bounding_Coordinate": float(np.nanmin(lat_d)),
            "N_Algorithm_Version": "2.O.000.001",
            "N_Aux_Filename": [a.format(p=p) for a in aux],
            "N_Anc_Filename": ["Terrain-Eco-ANC-Tile_20030125000000Z_ee00000000000000Z_NA_NA_S0388_1.O.0.0"],
            "N_Beginning_Orbit_Number": satellite_info(p).orbit_number(begin),
            "N_Beginning_Time_IET": begin_iet,
            "N_Ending_Time_IET": end_iet,
            "N_Granule_ID": gid,
            "N_Granule_Status": "N/A",
            "N_Granule_Version": "A1",
            "N_IDPS_Mode": "ops",
            "N_Number_Of_Scans": nscan,
            "N_Software_Version": self.spec.software_version,
            "N_Spacecraft_Maneuver": "Normal Operations",
            "N_Primary_Label": "Primary",
            **date_time_attrs("N_Creation", _utc(end + 1700)),
        }

    def viirs_granule_starts(self) -> np.ndarray:
        """Start times (unix s) of the VIIRS granules that cover the CrIS granules with margin.

        Returns
        -------
        numpy.ndarray
            Unix s.
        """
        first = self.t0 - 5.0
        last = self.t0 + self.spec.granules * CRIS_GRANULE_S + 5.0
        ref = self.t0 - self.spec.viirs_lead_s
        k0 = int(np.floor((first - ref) / VIIRS_GRANULE_S))
        k1 = int(np.floor((last - ref) / VIIRS_GRANULE_S))
        return ref + np.arange(k0, k1 + 1) * VIIRS_GRANULE_S


def simulate_case(
    out_dir: str | os.PathLike[str],
    spec: SimulationSpec | None = None,
    viirs: bool = True,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[], None] | None = None,
    **parameters: Any,
) -> dict:
    """Write a case's granules into *out_dir* and ``truth.json``; return the truth document. The case is
    *spec*, or a :class:`SimulationSpec` of *parameters* (its fields: a name it does not declare is a
    TypeError). *viirs* False: the CrIS granules alone. *should_stop*, polled between granules and between
    a VIIRS granule's scans, ends the simulation with :class:`StopRequested` (what was written stays: the
    caller decides).

    Parameters
    ----------
    out_dir : str or os.PathLike
        The case's directory.
    spec : SimulationSpec, optional
        The case; else one of *parameters*.
    viirs : bool, optional
        Also the VIIRS granules.
    should_stop : callable, optional
        Polled between granules and scans; True ends it with :class:`StopRequested`.
    progress : callable, optional
        Called after each granule written (CrIS, then each VIIRS grid's); if it has ``begin(total)``, that
        is called first with the granules there will be.
    **parameters : object
        :class:`SimulationSpec`'s fields.

    Returns
    -------
    dict
        The truth document (``truth.json``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    spec = spec or SimulationSpec(**parameters)
    sim = Simulator(spec)
    stop = should_stop or (lambda: False)
    files = []
    done = progress or (lambda: None)
    grids = [g for g in GRIDS.values() if any(BANDS[b].resolution == g.resolution for b in spec.viirs_bands)]
    starts = sim.viirs_granule_starts() if viirs else np.zeros(0)
    begin = getattr(progress, "begin", None)
    if begin is not None:
        begin(spec.granules + len(starts) * len(grids))
    for k in range(spec.granules):
        if stop():
            raise StopRequested
        files += sim.cris_granule(k, out)
        done()
    for g0 in starts:
        for grid in grids:
            files += sim.viirs_granule(float(g0), out, should_stop=stop, grid=grid)
            done()
    truth = {
        "satellite": spec.satellite,
        "profile": spec.profile,
        "seed": spec.seed,
        "start": spec.start.isoformat(),
        "granules": spec.granules,
        "files": sorted(files),
        "first_granule_start": _utc(sim.t0).isoformat(),
        "orbit_pass": spec.orbit_pass,
        "pass_lon_deg": spec.pass_lon_deg,
        "terrain": spec.terrain,
        "cloud_heights": spec.cloud_heights,
        # the lift the clouds' law implies in the units the assessment learns it (parallax_m_per_k)
        "law_m_per_k": law_m_per_k(spec.satellite, spec.cloud_heights),
        "cloud_edges": spec.cloud_edges,
        "fov_rows_alpha_urad": spec.fov_rows_alpha_urad,
        "wind_in_track_m_s": spec.wind_in_track_m_s,
        "cloud_emissivity": spec.cloud_emissivity,
        "viirs_bands": list(spec.viirs_bands),
        "viirs_band_bias_k": {b: float(spec.viirs_band_bias_k.get(b, 0.0)) for b in spec.viirs_bands},
        "cris_calibration": {
            "bias_k": spec.cris_bias_k,
            "gain": spec.cris_gain,
            "nonlinear_k": spec.cris_nonlinear_k,
        },
        "cris_response": _response_doc(spec.cris_response),
        "engineering_packets": None
        if spec.true_ep is None or spec.ground_ep is None
        else {"true": spec.true_ep.version, "ground": spec.ground_ep.version},
        "fors": [
            {"for": k + 1, "d_alpha_urad": float(a), "d_beta_urad": float(b)}
            for k, (a, b) in enumerate(zip(spec.d_alpha_urad, spec.d_beta_urad, strict=True))
        ],
    }
    (out / "truth.json").write_text(json.dumps(truth, indent=1))
    return truth


def _response_doc(response: Response | tuple[Response, ...] | None) -> list | None:
    """The truth's record of the CrIS spatial response: per FOV its full widths (deg) at 70, 50, 10 and
    3 % (of the azimuthal mean where it is elliptical, with its axes' stretch and angle) and the knots of the
    radial profile; None for the top-hat cone."""
    if response is None:
        return None
    each = response if isinstance(response, tuple) else (response,) * N_FOV
    docs = []
    for k, r in enumerate(each):
        radial = r.radial if isinstance(r, EllipticalResponse) else r
        doc = {
            "fov": k + 1,
            "full_width_deg": {
                f"{round(100 * lv)}%": float(np.degrees(r.full_width_rad(lv))) for lv in (0.7, 0.5, 0.1, 0.03)
            },
            "radius_rad": list(radial.radius_rad),
            "response": list(radial.response),
        }
        if isinstance(r, EllipticalResponse):
            doc["stretch"] = {"a": r.scale_a, "b": r.scale_b, "angle_deg": math.degrees(r.angle_rad)}
        docs.append(doc)
    return docs
