"""The VIIRS bands CrIS shares, and the two VIIRS pixel grids they lie on: one table of each.

CrIS's long-wave band (650-1095 cm-1) holds VIIRS I5 (11.45 um), M15 (10.76 um) and M16 (12.01 um); its
short-wave band (2155-2550 cm-1) holds M13 (4.05 um). These are the four bands in which CrIS and VIIRS are
compared (Tobin et al. 2013's intercomparison; the AAPP CrIS-VIIRS mapping of Brunel, Roquet and
Atkinson). Grid facts: docs/jpss-formats.md section 3 (``VcstGeoParameters.h``: aggregation zones; cwutils
``VIIRSIBandSDRParams.java`` and ``VIIRSBowtieFilter.java``: bow-tie deletion). Product facts: section 1.7
(M13's brightness temperature is float32, the others uint16 with scale factors).
"""

from __future__ import annotations

from dataclasses import dataclass

from monitor.core.constants import DEFAULT_STEP_RAD, VIIRS_COLUMNS, VIIRS_DETECTORS
from monitor.core.errors import DataError

ZONE_AGGREGATION = (1, 2, 3, 2, 1)  # native samples per output sample in the five aggregation zones
I_NATIVE_RAD = 155.2e-6  # an I-band native sample along the scan; 12608 of them span +-56 deg


@dataclass(frozen=True)
class ViirsGrid:
    """One VIIRS pixel grid (I or M): its detectors (rows of a scan), output columns and geometry.

    ``bowtie`` lists, per group of detector rows, the output samples deleted on board at each end of the
    row (the bow-tie deletion); ``geo_prefixes`` the GEO products on this grid, the preferred (terrain
    corrected, the only one NOAA's archive carries) first. ``smoothed_cones``: the grid's pixels are wider
    than the perturbation step, and the cone sums are smoothed over neighbouring perturbations
    (:func:`monitor.collocation.sums.smoothed`).
    """

    resolution: str
    detectors: int
    columns: int
    zone_columns: tuple[int, ...]
    native_rad: float
    detector_rad: float
    bowtie: tuple[tuple[tuple[int, ...], int], ...]
    geo_prefixes: tuple[str, ...]
    geo_collections: tuple[str, ...]
    smoothed_cones: bool


GRIDS = {
    g.resolution: g
    for g in (
        ViirsGrid(
            "I",
            VIIRS_DETECTORS,
            VIIRS_COLUMNS,
            (1280, 736, 2368, 736, 1280),
            I_NATIVE_RAD,
            DEFAULT_STEP_RAD,
            (((0, 1, 30, 31), 2016), ((2, 3, 28, 29), 1280)),
            ("GITCO", "GIMGO"),
            ("VIIRS-IMG-GEO-TC", "VIIRS-IMG-GEO"),
            False,
        ),
        ViirsGrid(
            "M",
            VIIRS_DETECTORS // 2,
            VIIRS_COLUMNS // 2,
            (640, 368, 1184, 368, 640),
            2 * I_NATIVE_RAD,
            2 * DEFAULT_STEP_RAD,
            (((0, 15), 1008), ((1, 14), 640)),
            ("GMTCO", "GMODO"),
            ("VIIRS-MOD-GEO-TC", "VIIRS-MOD-GEO"),
            True,
        ),
    )
}


@dataclass(frozen=True)
class ViirsBand:
    """One VIIRS band CrIS shares: its grid, SDR product, spectral response file tag, CrIS band and nominal
    central wavelength.

    ``min_scene_k`` is the scene brightness temperature below which CrIS's noise in the band's CrIS band
    swamps a comparison (M13: the short-wave band's NEdN at cold scenes); None where every scene serves.
    """

    name: str
    resolution: str
    sdr_prefix: str
    sdr_collection: str
    srf_tag: str
    cris_band: str  # "LW" or "SW": the CrIS band that holds the VIIRS band
    bt_scaled: bool  # uint16 with BrightnessTemperatureFactors (M13: float32)
    quality_dataset: str
    centre_um: float  # the band's nominal central wavelength, um
    min_scene_k: float | None = None

    @property
    def grid(self) -> ViirsGrid:  # numpydoc ignore=RT01
        """The band's pixel grid."""
        return GRIDS[self.resolution]


BANDS = {
    b.name: b
    for b in (
        ViirsBand("I5", "I", "SVI05", "VIIRS-I5-SDR", "i05", "LW", True, "QF1_VIIRSIBANDSDR", 11.45),
        ViirsBand("M13", "M", "SVM13", "VIIRS-M13-SDR", "m13", "SW", False, "QF1_VIIRSMBANDSDR", 4.05, 260.0),
        ViirsBand("M15", "M", "SVM15", "VIIRS-M15-SDR", "m15", "LW", True, "QF1_VIIRSMBANDSDR", 10.763),
        ViirsBand("M16", "M", "SVM16", "VIIRS-M16-SDR", "m16", "LW", True, "QF1_VIIRSMBANDSDR", 12.013),
    )
}
DEFAULT_BANDS = ("I5",)  # the assessment's band; the others when asked for


def parse_bands(text: str) -> tuple[str, ...]:
    """Band names from a comma-separated list (``I5,M15``), in the table's order, each once.

    Parameters
    ----------
    text : str
        Band names, comma-separated, any case.

    Returns
    -------
    tuple of str
        The bands, in the order of :data:`BANDS`.
    """
    asked = [t.strip().upper() for t in text.split(",") if t.strip()]
    unknown = [t for t in asked if t not in BANDS]
    if unknown or not asked:
        raise DataError(f"bands {text!r}: each must be one of {', '.join(BANDS)}")
    return tuple(b for b in BANDS if b in asked)
