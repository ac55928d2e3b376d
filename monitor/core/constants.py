"""The instrument constants, in one place: CrIS scan and FOV, the VIIRS I-band pixel, the paper's grid.

Everything else derives from these (never retype 30 or 16807.5).
"""

URAD = 1e-6  # radians per microradian (EP files and reports hold urad)

N_FOR = 30  # CrIS fields of regard (scan positions) per scan
N_FOV = 9  # CrIS fields of view per FOR (3 x 3)
PAPER_GRANULES = 14  # the granules of the paper's day (Wang et al. 2017: 14 granules x 4 scans x 9 FOVs)
FOV_DIAMETER_URAD = 16807.5  # CrIS FOV size, 0.963 deg (Wang et al. 2017; the EP files carry 16808)
FOV_DIAMETER_RAD = FOV_DIAMETER_URAD * URAD
FOV_HALF_ANGLE_RAD = FOV_DIAMETER_RAD / 2  # the paper's cone: its radius about the LOS
FOV_SPACING_RAD = 19.1e-3  # CrIS FOV centre spacing, ~1.1 deg (EP offsets, docs/jpss-formats.md 2.1)

CRIS_SCAN_US = 8_000_000  # CrIS scan period (IET microseconds)
CRIS_SCANS_PER_GRANULE = 4
CRIS_GRANULE_US = CRIS_SCANS_PER_GRANULE * CRIS_SCAN_US  # a CrIS granule, 32 s
VIIRS_SCAN_US = 1_786_400  # VIIRS scan period, 1.7864 s
VIIRS_DETECTORS = 32  # VIIRS I-band detectors: the rows of one scan
VIIRS_SCANS = 48  # scans a VIIRS granule's arrays always hold (those past N_Number_Of_Scans are fill)
VIIRS_COLUMNS = 6400  # I-band samples per row

SPEC_KM = 1.5  # the CrIS geolocation specification (each of in-track and cross-track), km

# CrIS-VIIRS intercalibration: the BT about which a gain difference turns (the bias is reported there) and
# the width of the BT bins of the difference against the CrIS BT (the paper's Figure 15)
CALIBRATION_REFERENCE_K = 280.0
CALIBRATION_BIN_K = 10.0
# a curvature of the difference is stated as its value this far from the reference (at 250 and 310 K)
CALIBRATION_CURVATURE_SPAN_K = 30.0

VIIRS_I_PIXEL_M = 375.0  # VIIRS I-band pixel at nadir
REFERENCE_ALTITUDE_M = 833000.0  # the JPSS orbit altitude the paper's grid step is defined at
DEFAULT_STEP_RAD = VIIRS_I_PIXEL_M / REFERENCE_ALTITUDE_M  # one I-band pixel seen from 833 km, ~450 urad
DEFAULT_STEP_URAD = DEFAULT_STEP_RAD / URAD
# A FOV-5 angle of the LOS fingerprint moving more than this (urad) is a geolocation processing change (real
# NOAA-20: granules 1-7 depart at most 3.4 urad from the median of 1-5, the scan-to-scan scatter is ~2 urad;
# those after the servo's move, 10-25). The fingerprint's change test and the residual table's staleness test
# use it.
PROCESSING_CHANGE_URAD = 10.0
DEFAULT_HALF_STEPS = 10  # perturbations on each side of zero: a 21 x 21 grid
# The widest perturbation grid the compiled cone kernel takes: half_steps^2 x step <= 0.2 rad (the paper's
# grid: 100 x 450 urad = 0.045 rad); within it tan B_j is linear in j to 0.3 of a step at |beta| <= 55 deg.
MAX_GRID_SPREAD_RAD = 0.2
