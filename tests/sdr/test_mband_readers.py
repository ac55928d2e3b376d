"""The M-band readers (SVM13, SVM15, SVM16, GMTCO): the grid, the fills, aggregated files, pairing."""

from __future__ import annotations

import datetime as dt

import h5py
import numpy as np
import pytest

from monitor.core.bands import BANDS, GRIDS
from monitor.sdr import GranuleError, read_file
from monitor.sdr.pairing import plan
from monitor.sdr.products import PRODUCTS
from monitor.sdr.readers import read_metadata
from monitor.simulate.case import simulate_case
from monitor.simulate.jpss_h5 import ProductData, write_file
from tests.sdr.test_readers import _gran_attrs


@pytest.fixture(scope="module")
def two_viirs(tmp_path_factory):
    """One CrIS granule with two M15 (and M13) granules under it: the VIIRS granules start 80 s before."""
    out = tmp_path_factory.mktemp("mband")
    simulate_case(out, granules=1, profile="zero", seed=4, viirs_bands=("M13", "M15"), viirs_lead_s=80.0)
    return out


def test_m_band_granules_read_on_their_grid(two_viirs):
    grid = GRIDS["M"]
    for prefix in ("SVM15", "SVM13"):
        (g,) = read_file(sorted(two_viirs.glob(f"{prefix}_*.h5"))[0])
        assert g.bt_k.shape == (48 * grid.detectors, grid.columns)
        assert g.meta.product == prefix
        good = g.bt_k[g.good]
        assert good.size > 0.8 * g.bt_k.size and 200 < np.median(good) < 320
    (geo,) = read_file(sorted(two_viirs.glob("GMTCO_*.h5"))[0])
    assert geo.lat_rad.shape == (768, 3200) and geo.height_m is not None
    # the bow-tie deletion of rows 0 and 15 of every scan, their first 1008 and last 1008 columns
    deleted = ~np.isfinite(geo.lat_rad.reshape(48, 16, 3200))
    assert deleted[:, 0, :1008].all() and deleted[:, 15, -1008:].all() and not deleted[:, 4:12].any()


def test_m13_is_float_and_the_others_scaled(two_viirs):
    with h5py.File(sorted(two_viirs.glob("SVM13_*.h5"))[0]) as h5:
        assert h5["All_Data/VIIRS-M13-SDR_All/BrightnessTemperature"].dtype == np.float32
        assert "BrightnessTemperatureFactors" not in h5["All_Data/VIIRS-M13-SDR_All"]
    with h5py.File(sorted(two_viirs.glob("SVM15_*.h5"))[0]) as h5:
        assert h5["All_Data/VIIRS-M15-SDR_All/BrightnessTemperature"].dtype == np.uint16
    assert not BANDS["M13"].bt_scaled and BANDS["M15"].bt_scaled


def _aggregate(files, prefix, out):
    product = PRODUCTS[prefix]
    data, attrs = {}, []
    group = f"All_Data/{product.collection}_All"
    for f in files:
        with h5py.File(f, "r") as h5:
            for k in h5[group]:
                data.setdefault(k, []).append(h5[group][k][()])
            attrs.append(_gran_attrs(h5, product.collection))
    data = {k: np.concatenate(v) for k, v in data.items()}
    rows = {k: v.shape[0] // len(files) for k, v in data.items()}
    write_file(
        out,
        "j01",
        dt.datetime(2024, 6, 2, tzinfo=dt.timezone.utc),
        [ProductData(product, "VIIRS", "SDR" if prefix.startswith("SV") else "GEO", data, attrs, rows)],
    )
    return out


@pytest.mark.parametrize("prefix", ["SVM15", "SVM13", "GMTCO"])
def test_an_aggregated_file_splits_into_its_granules(two_viirs, tmp_path, prefix):
    files = sorted(two_viirs.glob(f"{prefix}_*.h5"))
    assert len(files) == 2
    name = files[0].name.split("_c")[0] + "_c20240602000000000000_oebc_ops.h5"
    agg = _aggregate(files, prefix, tmp_path / name)
    grans = read_file(agg)
    singles = [read_file(f)[0] for f in files]
    assert [g.meta.granule_id for g in grans] == [s.meta.granule_id for s in singles]
    key = "lat_rad" if prefix == "GMTCO" else "bt_k"
    for g, s in zip(grans, singles, strict=True):
        np.testing.assert_array_equal(getattr(g, key), getattr(s, key))
    assert len(read_metadata(agg)) == 2


def test_a_damaged_m_band_file_names_file_and_field(two_viirs, tmp_path):
    src = sorted(two_viirs.glob("SVM15_*.h5"))[0]
    bad = tmp_path / src.name
    bad.write_bytes(src.read_bytes())
    with h5py.File(bad, "r+") as h5:
        del h5["All_Data/VIIRS-M15-SDR_All/QF1_VIIRSMBANDSDR"]
    with pytest.raises(GranuleError) as err:
        read_file(bad)
    assert bad.name in str(err.value) and "QF1_VIIRSMBANDSDR: missing dataset" in str(err.value)


def test_m_band_granules_pair_with_their_geolocation_and_cover_cris_by_time(two_viirs):
    case = plan([two_viirs], bands=("M13", "M15"))
    (cris,) = case.cris_all
    assert case.viirs_all == []  # no I5 in this case: the assessment's pairing sees none
    for band in ("M13", "M15"):
        cover = case.cover(cris, band)
        assert len(cover) == 2 and all(v.geo.name.startswith("GMTCO") for v in cover)
        assert all(v.sdr.name.startswith(BANDS[band].sdr_prefix) for v in cover)
