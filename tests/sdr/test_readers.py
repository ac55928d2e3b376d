import datetime as dt
import shutil

import h5py
import numpy as np
import pytest

from monitor.sdr import GranuleError, read_file
from monitor.sdr.products import PRODUCTS
from monitor.sdr.readers import read_metadata, read_viirs_geo_scan
from monitor.simulate.case import simulate_case
from monitor.simulate.jpss_h5 import ProductData, write_file


def test_real_gcrso_fields_units_and_metadata(real_geo_files):
    (g,) = read_file(real_geo_files[0])
    assert g.meta.platform == "j01" and g.meta.granule_id == "J01002208398383" and g.meta.n_scans == 4
    assert g.meta.software_version == "I2.1.03.00" and g.meta.algorithm_version == "2.O.000.001"
    assert any(a.startswith("CMNGEO-PARAM-LUT_j01") for a in g.meta.aux_files)
    assert any(a.startswith("CrIS-SDR-ENGPKT-BACKUP-AUX") for a in g.meta.aux_files)
    assert g.meta.start == dt.datetime(2018, 10, 22, 0, 23, 59, 983966, tzinfo=dt.timezone.utc)
    assert g.lat_rad.shape == (4, 30, 9) and g.for_time_us.shape == (4, 30)
    assert np.all(np.abs(g.lat_rad) < np.pi / 2) and g.valid.all()
    assert 833e3 < g.range_m.min() < 840e3 and 1.4e6 < g.range_m.max() < 1.5e6
    # SCAttitude is arcseconds in the file: ~0.03-0.8 arcsec -> ~1e-7..4e-6 rad
    assert np.all(np.abs(g.sc_attitude_rad) < 5e-6)
    # Large negative positions are values, not fills
    assert np.all(np.isfinite(g.sc_position_m)) and np.min(g.sc_position_m) < -1000


def _copy(src, dst):
    shutil.copy(src, dst)
    dst.chmod(0o644)
    return dst


def test_truncated_and_non_hdf5_files_name_the_file(real_geo_files, tmp_path):
    bad = tmp_path / real_geo_files[0].name
    bad.write_bytes(real_geo_files[0].read_bytes()[:20000])
    with pytest.raises(GranuleError) as e:
        read_file(bad)
    assert str(bad) in str(e.value) and "HDF5" in str(e.value)
    text = tmp_path / "GCRSO_j01_d20181022_t0023599_e0024297_b04790_c20181022005852745013_noac_ops.h5"
    text.write_text("not hdf5")
    with pytest.raises(GranuleError, match="not a readable HDF5 file"):
        read_file(text)


def test_missing_dataset_is_named(real_geo_files, tmp_path):
    f = _copy(real_geo_files[0], tmp_path / real_geo_files[0].name)
    with h5py.File(f, "r+") as h5:
        del h5["All_Data/CrIS-SDR-GEO_All/SatelliteRange"]
    with pytest.raises(GranuleError) as e:
        read_file(f)
    assert e.value.field == "All_Data/CrIS-SDR-GEO_All/SatelliteRange" and e.value.reason == "missing dataset"


def test_all_fill_granule_is_rejected_and_partial_fill_masked(real_geo_files, tmp_path):
    f = _copy(real_geo_files[0], tmp_path / real_geo_files[0].name)
    with h5py.File(f, "r+") as h5:
        for name in ("Latitude", "Longitude"):
            h5[f"All_Data/CrIS-SDR-GEO_All/{name}"][1, 5, :] = -999.3
    (g,) = read_file(f)
    assert np.isnan(g.lat_rad[1, 5]).all() and not g.valid[1, 5].any() and g.valid[0].all()
    with h5py.File(f, "r+") as h5:
        h5["All_Data/CrIS-SDR-GEO_All/Latitude"][...] = -999.9
    with pytest.raises(GranuleError, match="only fill values"):
        read_file(f)


def test_wrong_axis0_is_reported(real_geo_files, tmp_path):
    f = _copy(real_geo_files[0], tmp_path / real_geo_files[0].name)
    with h5py.File(f, "r+") as h5:
        del h5["All_Data/CrIS-SDR-GEO_All/FORTime"]
        h5["All_Data/CrIS-SDR-GEO_All/FORTime"] = np.zeros((3, 30), np.int64)
    with pytest.raises(GranuleError, match=r"FORTime: shape \(3, 30\), expected \(4, 30\)"):
        read_file(f)
    with h5py.File(f, "r+") as h5:  # every axis is checked, not only the first
        del h5["All_Data/CrIS-SDR-GEO_All/FORTime"]
        h5["All_Data/CrIS-SDR-GEO_All/FORTime"] = np.zeros((4, 29), np.int64)
    with pytest.raises(GranuleError, match=r"FORTime: shape \(4, 29\), expected \(4, 30\)"):
        read_file(f)


@pytest.mark.parametrize(
    "dataset,value,reason",
    [
        ("Latitude", 1e28, r"value 1e\+28 outside -90..90"),
        ("SatelliteRange", 10.0, r"value 10 outside 700000..4e\+06"),
        ("SCPosition", 7e9, "vector length .* outside"),
    ],
)
def test_out_of_range_values_are_refused(real_geo_files, tmp_path, dataset, value, reason):
    f = _copy(real_geo_files[0], tmp_path / real_geo_files[0].name)
    with h5py.File(f, "r+") as h5:
        d = h5[f"All_Data/CrIS-SDR-GEO_All/{dataset}"]
        a = d[()]
        a.flat[5] = value
        d[...] = a
    with pytest.raises(GranuleError, match=f"{f.name}: All_Data/CrIS-SDR-GEO_All/{dataset}: {reason}"):
        read_file(f)


def test_times_and_platform_must_match_the_granule(real_geo_files, tmp_path):
    f = _copy(real_geo_files[0], tmp_path / real_geo_files[0].name)
    with h5py.File(f, "r+") as h5:
        t = h5["All_Data/CrIS-SDR-GEO_All/FORTime"]
        t[...] = t[()] - 3_600_000_000
    with pytest.raises(GranuleError, match="FORTime: time .* outside the granule"):
        read_file(f)
    f = _copy(real_geo_files[1], tmp_path / real_geo_files[1].name)
    with h5py.File(f, "r+") as h5:
        h5.attrs["Platform_Short_Name"] = np.array([[b"NPP"]])
    with pytest.raises(GranuleError, match="Platform_Short_Name: 'NPP' in a file named for j01"):
        read_file(f)
    f = _copy(real_geo_files[2], tmp_path / real_geo_files[2].name)
    with h5py.File(f, "r+") as h5:
        h5["Data_Products/CrIS-SDR-GEO/CrIS-SDR-GEO_Gran_0"].attrs["N_Number_Of_Scans"] = np.array(
            [[b"four"]]
        )
    with pytest.raises(GranuleError, match="N_Number_Of_Scans: not a number: 'four'"):
        read_file(f)


def _gran_attrs(h5, coll):
    a = h5[f"Data_Products/{coll}/{coll}_Gran_0"].attrs
    out = {}
    for k, v in a.items():
        v = np.asarray(v)
        if v.dtype.kind == "S":
            items = [x.decode() for x in v.ravel()]
            out[k] = items[0] if v.size == 1 and k not in ("N_Aux_Filename", "N_Anc_Filename") else items
        else:
            out[k] = v.ravel()[0].item()
    return out


def test_aggregated_file_splits_into_granules(real_geo_files, tmp_path):
    product = PRODUCTS["GCRSO"]
    data, attrs = {}, []
    for f in real_geo_files[:3]:
        with h5py.File(f, "r") as h5:
            g = h5["All_Data/CrIS-SDR-GEO_All"]
            for k in g:
                data.setdefault(k, []).append(g[k][()])
            attrs.append(_gran_attrs(h5, "CrIS-SDR-GEO"))
    data = {k: np.concatenate(v) for k, v in data.items()}
    out = tmp_path / "GCRSO_j01_d20181022_t0023599_e0025337_b04790_c20181022010000000000_noac_ops.h5"
    write_file(
        out,
        "j01",
        dt.datetime(2018, 10, 22, 1, tzinfo=dt.timezone.utc),
        [ProductData(product, "CrIS", "GEO", data, attrs, {k: 4 for k in data})],
    )
    grans = read_file(out)
    assert [g.meta.granule_id for g in grans] == [read_file(f)[0].meta.granule_id for f in real_geo_files[:3]]
    for g, f in zip(grans, real_geo_files[:3], strict=True):
        single = read_file(f)[0]
        np.testing.assert_array_equal(g.lat_rad, single.lat_rad)
        np.testing.assert_array_equal(g.for_time_us, single.for_time_us)
    assert len(read_metadata(out)) == 3
    with h5py.File(out, "r") as h5:  # region references point at each granule's scans
        ref = h5["Data_Products/CrIS-SDR-GEO/CrIS-SDR-GEO_Gran_1"][0]
        assert h5[ref][ref].shape[0] == 4


@pytest.fixture(scope="module")
def sim_cris(tmp_path_factory):
    out = tmp_path_factory.mktemp("cris_only")
    simulate_case(out, granules=1, profile="zero", seed=5, viirs=False)
    return out


def test_simulated_cris_sdr_geo_read_back(sim_cris):
    (geo,) = read_file(next(sim_cris.glob("GCRSO_*.h5")))
    (sdr,) = read_file(next(sim_cris.glob("SCRIF_*.h5")))
    assert sdr.radiance_lw.shape == (4, 30, 9, 717) and sdr.good.all()
    assert sdr.wavenumber_cm1[0] == 648.75 and sdr.wavenumber_cm1[-1] == pytest.approx(1096.25)
    assert geo.valid.all() and geo.meta.granule_id == sdr.meta.granule_id
    with h5py.File(next(sim_cris.glob("GCRSO_*.h5")), "r") as h5:
        assert h5.userblock_size == 1024
        assert h5.attrs["Platform_Short_Name"].shape == (1, 1)
    head = next(sim_cris.glob("GCRSO_*.h5")).read_bytes()[:1024]
    assert head.startswith(b"<HDF_UserBlock>") and b"CrIS-SDR-GEO" in head


def test_combined_file_holds_both_products(sim_cris, tmp_path):
    geo_file = next(sim_cris.glob("GCRSO_*.h5"))
    sdr_file = next(sim_cris.glob("SCRIF_*.h5"))
    parts = []
    for f, prefix, tag in ((geo_file, "GCRSO", "GEO"), (sdr_file, "SCRIF", "SDR")):
        p = PRODUCTS[prefix]
        with h5py.File(f, "r") as h5:
            data = {k: v[()] for k, v in h5[p.data_group].items()}
            parts.append(ProductData(p, "CrIS", tag, data, [_gran_attrs(h5, p.collection)], {}))
    out = tmp_path / geo_file.name.replace("GCRSO_", "GCRSO-SCRIF_")
    write_file(out, "j01", dt.datetime(2024, 6, 1, tzinfo=dt.timezone.utc), parts)
    kinds = sorted(type(g).__name__ for g in read_file(out))
    assert kinds == ["CrisGeoGranule", "CrisSdrGranule"]


def test_viirs_files_scaled_and_bowtie_filled(cases):
    out, _, _ = cases.get()
    (sdr,) = read_file(next(out.glob("SVI05_*.h5")))
    (geo,) = read_file(next(out.glob("GITCO_*.h5")))
    assert sdr.bt_k.shape == geo.lat_rad.shape == (1536, 6400)
    assert 180 < np.nanmin(sdr.bt_k) and np.nanmax(sdr.bt_k) < 330
    # bow-tie deletion: detector rows 0, 1, 30, 31 lose the first and last 2016 samples
    assert np.isnan(sdr.bt_k[0, :2016]).all() and np.isfinite(sdr.bt_k[0, 2016:4384]).all()
    assert np.isnan(geo.lat_rad[31, -2016:]).all() and np.isfinite(geo.lat_rad[15]).all()
    assert np.isnan(sdr.bt_k[2, :1280]).all() and np.isfinite(sdr.bt_k[2, 1280]).all()
    lat, lon, height = read_viirs_geo_scan(next(out.glob("GITCO_*.h5")), -1)
    np.testing.assert_array_equal(lat, geo.lat_rad[-32:])
    np.testing.assert_array_equal(height, geo.height_m[-32:])


def _edit(path, dataset, edit):
    with h5py.File(path, "r+") as h5:
        d = h5[f"{PRODUCTS['GITCO'].data_group}/{dataset}"]
        d[...] = edit(d[()])


def test_gitco_height_is_read_and_checked(cases, tmp_path):
    out, _, _ = cases.get()
    src = next(out.glob("GITCO_*.h5"))
    (geo,) = read_file(src)
    assert geo.height_m.shape == geo.lat_rad.shape
    assert np.array_equal(np.isnan(geo.height_m), np.isnan(geo.lat_rad))  # fill only where the pixel is fill
    for dataset, edit, reason in (
        (
            "Height",
            lambda h: np.where(np.arange(h.shape[1]) == 3000, np.float32(-999.3), h),
            "fill or non-finite",
        ),
        ("Height", lambda h: np.where(h > -999, np.float32(12000.0), h), "outside -500..9000 m"),
    ):
        bad = _copy(src, tmp_path / src.name)
        _edit(bad, dataset, edit)
        with pytest.raises(GranuleError, match=f"{bad.name}: .*/Height: .*{reason}"):
            read_file(bad)
        bad.unlink()
    bad = _copy(src, tmp_path / src.name)
    with h5py.File(bad, "r+") as h5:
        del h5[f"{PRODUCTS['GITCO'].data_group}/Height"]
    with pytest.raises(GranuleError, match="Height: missing dataset"):
        read_file(bad)


def test_gimgo_pixels_are_on_the_ellipsoid(cases, tmp_path):
    """The ellipsoid product has no Height: its pixels are at h = 0."""
    out, _, _ = cases.get()
    src = next(out.glob("GITCO_*.h5"))
    with h5py.File(src, "r") as h5:
        p = PRODUCTS["GITCO"]
        data = {k: v[()] for k, v in h5[p.data_group].items() if k != "Height"}
        attrs = _gran_attrs(h5, p.collection)
    dst = tmp_path / src.name.replace("GITCO_", "GIMGO_")
    write_file(
        dst,
        "j01",
        dt.datetime(2024, 6, 1, tzinfo=dt.timezone.utc),
        [ProductData(PRODUCTS["GIMGO"], "VIIRS", "GEO", data, [attrs], {}, fills={}, compress=False)],
    )
    (geo,) = read_file(dst)
    assert np.all(geo.height_m == 0) and read_viirs_geo_scan(dst, 0)[2].max() == 0


def test_longitudes_all_fill_under_set_latitudes_are_refused(cases, tmp_path):
    """A VIIRS GEO whose longitudes are all NaN used to end the assessment with a numpy ValueError."""
    out, _, _ = cases.get()
    src = next(out.glob("GITCO_*.h5"))
    bad = _copy(src, tmp_path / src.name)
    _edit(bad, "Longitude", lambda a: np.full_like(a, np.nan))
    with pytest.raises(GranuleError, match=f"{bad.name}: .*/Longitude: fill at .* where Latitude is set"):
        read_file(bad)


def test_an_sdr_and_a_geo_of_different_granules_are_not_paired(cases, tmp_path):
    """A GEO file of the next granule under the name of this granule's GEO: each file is consistent in
    itself (its ID is its own time's, its name 32 s from its content is within the 60 s allowed), but the
    two are not one granule."""
    from monitor.sdr.pairing import granule_files, plan

    base, _, _ = cases.get()
    for f in base.glob("*.h5"):
        (tmp_path / f.name).symlink_to(f)
    first, second = sorted(base.glob("GCRSO_*.h5"))[:2]
    (tmp_path / first.name).unlink()
    shutil.copyfile(second, tmp_path / first.name)
    skipped = dict(plan([tmp_path]).skipped)
    sdr = next(p for p in skipped if "SCRIF" in p)
    assert "not the granule of its GEO file" in skipped[sdr] and "its GEO holds" in skipped[sdr]
    with pytest.raises(GranuleError, match="N_Granule_ID: granule .* its GEO holds"):
        granule_files("k", sdr, tmp_path / first.name)
