"""Consistency checks on small arrays (the readers apply them to every granule: tests/sdr/test_fuzz.py)."""

from types import SimpleNamespace

import numpy as np
import pytest

from monitor.sdr import GranuleError
from monitor.sdr.geolocation import check_pixel_steps
from monitor.sdr.products import PRODUCTS

STEP_RAD = 0.4 / 6371.0  # 400 m, an I-band pixel


def _rows(lat0_deg, lon0_deg, n=64):
    """32 rows of n pixels marching east from (lat0, lon0), wrapped into -pi..pi."""
    lon = np.radians(lon0_deg) + STEP_RAD / np.cos(np.radians(lat0_deg)) * np.arange(n)
    lon = (lon + np.pi) % (2 * np.pi) - np.pi
    lat = np.full((32, n), np.radians(lat0_deg), np.float32)
    return SimpleNamespace(lat_rad=lat, lon_rad=np.tile(lon, (32, 1)).astype(np.float32))


@pytest.mark.parametrize("lat0, lon0", [(10.0, 20.0), (-5.0, 179.99), (88.0, -40.0)])
def test_genuine_rows_pass_across_the_antimeridian_and_near_a_pole(lat0, lon0):
    check_pixel_steps("f.h5", PRODUCTS["GITCO"], _rows(lat0, lon0))


def test_one_corrupt_pixel_is_named_with_its_row_and_column():
    g = _rows(10.0, 20.0)
    g.lat_rad[7, 30] = np.float32(np.radians(-0.19))  # 12 deg read back with its top byte flipped
    g.lat_rad[3, :10] = np.nan  # fill next to good pixels is no step
    with pytest.raises(GranuleError, match="row 7, columns 29-30: neighbouring pixels 113[34] km apart"):
        check_pixel_steps("f.h5", PRODUCTS["GITCO"], g)
