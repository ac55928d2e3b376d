import datetime as dt

import h5py
import numpy as np
import pytest

from monitor.sdr import iet
from monitor.sdr.names import format_name, parse_name

UTC = dt.timezone.utc


def test_parse_real_name_and_granule_key_pairs_sdr_with_geo():
    geo = parse_name("GCRSO_j01_d20181022_t0023599_e0024297_b04790_c20181022005852745013_noac_ops.h5")
    sdr = parse_name("SCRIF_j01_d20181022_t0023599_e0024297_b04790_c20181022005852736401_noac_ops.h5")
    assert geo.products == ("GCRSO",) and geo.platform == "j01" and geo.orbit == 4790
    assert geo.start == dt.datetime(2018, 10, 22, 0, 23, 59, 900000, tzinfo=UTC)
    assert geo.granule_key == sdr.granule_key == "j01_d20181022_t0023599_e0024297_b04790"
    assert geo.created != sdr.created


def test_combined_name_and_end_past_midnight():
    n = parse_name("GCRSO-SCRIF_npp_d20240601_t2359500_e0000198_b65000_c20240602000000000000_oebc_ops.h5")
    assert n.products == ("GCRSO", "SCRIF")
    assert n.end - n.start == dt.timedelta(seconds=29.8)


def test_non_jpss_names_are_rejected():
    assert parse_name("truth.json") is None
    assert parse_name("GCRSO_j01_d2018_t0023599.h5") is None


def test_format_name_round_trips():
    start = dt.datetime(2024, 6, 1, 12, 0, 0, 300000, tzinfo=UTC)
    name = format_name(
        ["SVI05"],
        "j02",
        start,
        start + dt.timedelta(seconds=85.7),
        123,
        dt.datetime(2024, 6, 1, 13, tzinfo=UTC),
    )
    p = parse_name(name)
    assert p.platform == "j02" and p.start == start and p.orbit == 123


def test_iet_matches_real_granule_attributes(real_geo_files):
    with h5py.File(real_geo_files[0], "r") as f:
        a = f["Data_Products/CrIS-SDR-GEO/CrIS-SDR-GEO_Gran_0"].attrs
        start_iet = int(a["N_Beginning_Time_IET"][0, 0])
        text = a["Beginning_Date"][0, 0].decode() + a["Beginning_Time"][0, 0].decode()
    expected = dt.datetime.strptime(text, "%Y%m%d%H%M%S.%fZ").replace(tzinfo=UTC)
    assert iet.iet_to_datetime(start_iet) == expected
    assert iet.datetime_to_iet(expected) == start_iet


@pytest.mark.parametrize(
    "when,offset_s",
    [
        (dt.datetime(2016, 12, 31, 23, 59, 59, tzinfo=UTC), 36),
        (dt.datetime(2017, 1, 1, 0, 0, 0, tzinfo=UTC), 37),
        (dt.datetime(2012, 6, 30, 12, 0, 0, tzinfo=UTC), 34),
    ],
)
def test_leap_seconds_around_changes(when, offset_s):
    naive_us = int((when - iet.IET_EPOCH).total_seconds()) * 1_000_000
    assert iet.datetime_to_iet(when) - naive_us == offset_s * 1_000_000
    assert iet.iet_to_datetime(iet.datetime_to_iet(when)) == when


def test_iet_arrays_round_trip():
    u = np.array([1.5e15, 1.7e15], dtype=np.int64)
    assert np.array_equal(iet.iet_to_unix_us(iet.unix_us_to_iet(u)), u)
