"""EP identification from the LOS fingerprint with the EP model."""

import json

import numpy as np

from monitor.cli import main
from monitor.mapping import fingerprint as fpr
from monitor.mapping.regeolocate import regeolocate_file
from monitor.sdr import read_file
from monitor.sdr.engpkt import load_library, packaged_ep


def _day(files):
    return fpr.day_print([fpr.granule_print(g) for f in files for g in read_file(f, kinds=("cris_geo",))])


def test_real_noaa20_fingerprint_is_v115(real_geo_files):
    day = _day(real_geo_files)
    library, problems = load_library([])
    assert not problems and set(library) == {"SNPP_side1_V37_EngPkt.xml", "JPSS1_side1_V115_EngPkt.xml"}
    ranked = fpr.identify_ep(day, library)
    assert ranked[0].version == "V115" and ranked[0].rms_urad < 40.0
    assert ranked[1].rms_urad > 10 * ranked[0].rms_urad
    # the known residual of the real processing: ~+28 urad in-track at every FOR (docs/jpss-formats.md 2.3)
    assert np.all(np.abs(ranked[0].d_alpha_urad - 28.0) < 5.0)
    assert [m.version for m in fpr.identify_ep(day, library, "j01")] == ["V115"]


def test_simulated_ep_change_is_identified(ep_geo_case, nominal_ep, error_ep, tmp_path):
    case, _ = ep_geo_case
    files = sorted(case.glob("GCRSO_*.h5"))
    library = {"nominal": nominal_ep, "paper_error": error_ep, "V37": packaged_ep("npp")}
    before = fpr.identify_ep(_day(files), library, "j01")
    assert before[0].name == "nominal" and before[0].rms_urad < 3.0
    after_files = [regeolocate_file(error_ep, f, tmp_path) for f in files]
    after = fpr.identify_ep(_day(after_files), library, "j01")
    assert after[0].name == "paper_error" and after[0].rms_urad < 3.0 and after[1].rms_urad > 100.0


def test_cli_fingerprint_reports_the_match(real_geo_files, tmp_path, capsys):
    bad = tmp_path / "broken.xml"
    bad.write_text("<EngPkt>")
    assert (
        main(
            [
                "fingerprint",
                "--json",
                "--ep-library",
                str(bad),
                "--ep-library",
                str(real_geo_files[0].parents[3] / "configs" / "ep"),
                *map(str, real_geo_files),
            ]
        )
        == 0
    )
    doc = json.loads(capsys.readouterr().out)
    assert doc["ep_match"][0]["name"] == "j01_nominal.yaml" and "broken.xml" in doc["ep_library_problems"][0]
    assert all(m["satellite"] == "j01" for m in doc["ep_match"])
