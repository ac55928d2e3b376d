"""Forward geolocation of GEO files with an EP, and regeolocated copies (the ADL role of section 4.2)."""

import hashlib
import json

import h5py
import numpy as np
import pytest

from monitor.cli import main
from monitor.core.errors import DataError
from monitor.mapping.regeolocate import compare_with_files, regeolocate_file
from monitor.sdr import read_file


def _geo_files(case):
    return sorted(case.glob("GCRSO_*.h5"))


def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_ground_ep_reproduces_simulated_geo(ep_geo_case, nominal_ep):
    case, _ = ep_geo_case
    rows = compare_with_files(nominal_ep, _geo_files(case))
    assert max(r.max_m for r in rows) < 5.0  # float32 storage and the propagation from MidTime


def test_regeolocated_copy_moves_by_the_ep_difference(ep_geo_case, nominal_ep, error_ep, tmp_path):
    case, truth = ep_geo_case
    files = _geo_files(case)
    before = [_digest(f) for f in files]
    out = [regeolocate_file(error_ep, f, tmp_path / "regeo") for f in files]
    assert [_digest(f) for f in files] == before  # inputs untouched
    assert max(r.max_m for r in compare_with_files(error_ep, out)) < 5.0
    shift = compare_with_files(nominal_ep, out)
    assert shift[29].median_m > 1500.0 and shift[4].median_m < shift[29].median_m  # end-of-scan growth
    (old,), (new,) = read_file(files[0]), read_file(out[0])
    assert np.array_equal(old.for_time_us, new.for_time_us) and np.array_equal(old.height_m, new.height_m)
    with h5py.File(out[0]) as h5:
        doc = json.loads(h5["All_Data/CrIS-SDR-GEO_All"].attrs["crisgeo_engineering_packet"])
        assert doc["version"] == error_ep.version
        north = float(
            np.asarray(
                h5["Data_Products/CrIS-SDR-GEO/CrIS-SDR-GEO_Gran_0"].attrs["North_Bounding_Coordinate"]
            ).ravel()[0]
        )
    assert north == pytest.approx(np.degrees(np.nanmax(new.lat_rad)), abs=1e-3)


def test_fills_are_kept_and_inputs_refused_in_place(ep_geo_case, nominal_ep, tmp_path):
    case, _ = ep_geo_case
    src = tmp_path / "in" / _geo_files(case)[0].name
    src.parent.mkdir()
    src.write_bytes(_geo_files(case)[0].read_bytes())
    with h5py.File(src, "r+") as h5:
        h5["All_Data/CrIS-SDR-GEO_All/Latitude"][1, 3, :] = -999.3  # IDPS fills a FOV's position whole
        h5["All_Data/CrIS-SDR-GEO_All/Longitude"][1, 3, :] = -999.3
    out = regeolocate_file(nominal_ep, src, tmp_path / "out")
    with h5py.File(out) as h5:
        lat = h5["All_Data/CrIS-SDR-GEO_All/Latitude"][()]
    assert np.all(lat[1, 3] < -999) and np.all(lat[0, 3] > -90)
    with pytest.raises(DataError, match="never touches its inputs"):
        regeolocate_file(nominal_ep, src, src.parent)


def test_cli_geolocate_json_on_real_granules(real_geo_files, capsys):
    from monitor.sdr.engpkt import packaged_path

    assert main(["geolocate", "--ep", str(packaged_path("j01")), "--json", *map(str, real_geo_files)]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [r["for"] for r in doc["fors"]] == list(range(1, 31))
    assert all(r["p99_m"] < 100 for r in doc["fors"][3:]) and all(r["median_m"] < 120 for r in doc["fors"])


def test_cli_regeolocate_and_wrong_satellite(ep_geo_case, tmp_path, capsys):
    case, _ = ep_geo_case
    files = list(map(str, _geo_files(case)))
    from monitor.sdr.engpkt import packaged_path

    assert main(["regeolocate", "--ep", str(packaged_path("npp")), "--out", str(tmp_path / "o"), *files]) == 2
    assert "granule of j01, EP V37 of npp" in capsys.readouterr().err
    bad = tmp_path / "GCRSO_j01_d20240601_t1200000_e1200300_b00001_c20240601123000000000_noac_ops.h5"
    bad.write_bytes(b"not hdf5")
    assert (
        main(
            [
                "regeolocate",
                "--ep",
                str(packaged_path("j01")),
                "--out",
                str(tmp_path / "o"),
                files[0],
                str(bad),
            ]
        )
        == 1
    )
    assert "skipped" in capsys.readouterr().err and (tmp_path / "o" / _geo_files(case)[0].name).exists()
