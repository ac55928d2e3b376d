"""EP files: the real decoded XML, the YAML form, writing a proposed EP, and malformed files."""

from pathlib import Path

import numpy as np
import pytest

from monitor.sdr.engpkt import EngPktError, load_ep, packaged_ep, packaged_path, save_ep

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "ep"


def test_real_xml_angles_satellite_and_mounting():
    ep = packaged_ep("j01")
    assert (ep.satellite, ep.version) == ("j01", "V115")
    assert ep.ssm_crosstrack_roll_rad[0] == pytest.approx(844883e-6)
    assert ep.ssm_intrack_pitch_rad[-1] == pytest.approx(2127e-6)
    assert ep.fov_crosstrack_offset_rad[2] == pytest.approx(-19112e-6)
    assert tuple(ep.ifr_boresight_to_ssmf_rad * 1e6) == pytest.approx((-536, 199))
    assert tuple(ep.iar_to_ssmr_rad * 1e6) == pytest.approx((-1254, 310, -1626))
    assert tuple(ep.sc_to_sbf_rad * 1e6) == pytest.approx((-145.84994, 267.42417, 594.61832))
    assert ep.time_stamp_bias_ms == -183
    npp = packaged_ep("npp")
    assert (npp.satellite, npp.version) == ("npp", "V37") and npp.los_relative_yaw_rad == pytest.approx(
        -359e-6
    )


def test_yaml_round_trip(tmp_path):
    ep = packaged_ep("npp")
    again = load_ep(save_ep(ep, tmp_path / "ep.yaml"))
    for name in (
        "ssm_crosstrack_roll_rad",
        "ssm_intrack_pitch_rad",
        "sc_to_sbf_rad",
        "iar_to_ssmr_rad",
        "fov_intrack_offset_rad",
        "ifr_boresight_to_ssmf_rad",
    ):
        assert np.allclose(getattr(again, name), getattr(ep, name), atol=1e-12), name
    assert again.satellite == "npp" and again.version == "V37"


def test_xml_output_changes_only_the_mirror_angles(tmp_path):
    src = packaged_path("j01")
    ep = load_ep(src)
    new = ep.with_ssm_angles(
        ep.ssm_crosstrack_roll_rad + 123.4e-6,
        ep.ssm_intrack_pitch_rad - 56.6e-6,
        provenance={"assessment": "x.json", "note": "a -- b"},
    )
    out = save_ep(new, tmp_path / "new.xml", like=src)
    back = load_ep(out)
    assert np.allclose(back.ssm_crosstrack_roll_rad, np.round(new.ssm_crosstrack_roll_rad * 1e6) * 1e-6)
    assert np.allclose(back.ssm_intrack_pitch_rad, np.round(new.ssm_intrack_pitch_rad * 1e6) * 1e-6)
    text, original = out.read_text(), src.read_text()
    assert "crisgeo provenance" in text and '"assessment": "x.json"' in text
    strip = lambda t: [ln for ln in t.splitlines() if "AnglePitch>" not in ln and "AngleRoll>" not in ln]  # noqa: E731
    body = text.split("-->\n", 1)[1]
    assert strip(body) == strip(original.split("\n", 1)[1])


def test_shipped_configs_load():
    for sat in ("npp", "j01", "j02"):
        ep = load_ep(CONFIGS / f"{sat}_nominal.yaml")
        assert ep.satellite == sat
    nominal, error = load_ep(CONFIGS / "j01_nominal.yaml"), load_ep(CONFIGS / "j01_paper_ssm_error.yaml")
    assert np.allclose(nominal.sc_to_sbf_rad, error.sc_to_sbf_rad)
    assert np.allclose(nominal.fov_intrack_offset_rad, error.fov_intrack_offset_rad)
    d_roll = (error.ssm_crosstrack_roll_rad - nominal.ssm_crosstrack_roll_rad) * 1e6
    assert abs(d_roll[-1]) == pytest.approx(1000.0) and np.all(d_roll[:10] == 0)


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda t: t[: len(t) // 2], "XML"),
        (
            lambda t: t.replace("<ActualCrosstrackAngleRoll>844883 ", "<ActualCrosstrackAngleRoll>"),
            "MappingParameters/ActualCrosstrackAngleRoll: expected 30 values, got 29",
        ),
        (
            lambda t: t.replace("<LosRelativeYaw>-520<", "<LosRelativeYaw>abc<"),
            "FovParam/Lw/LosRelativeYaw: not numbers",
        ),
        (
            lambda t: t.replace("<TimeStampBias>-183</TimeStampBias>", ""),
            "MappingParameters/TimeStampBias: missing",
        ),
        (
            lambda t: t.replace("<InstrumentId>4<", "<InstrumentId>9<"),
            "InstrumentId: 9 is not a known instrument",
        ),
        (lambda t: t.replace("<Pitch>310</Pitch>", "<Pitch>nan</Pitch>"), "non-finite"),
    ],
)
def test_malformed_xml_names_file_and_field(tmp_path, edit, field):
    bad = tmp_path / "bad.xml"
    bad.write_text(edit(packaged_path("j01").read_text()))
    with pytest.raises(EngPktError) as err:
        load_ep(bad)
    assert str(bad) in str(err.value) and field in str(err.value)


def test_malformed_yaml(tmp_path):
    good = save_ep(packaged_ep("j01"), tmp_path / "ep.yaml").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(good.replace("ScToSbf", "Mounting"))
    with pytest.raises(EngPktError, match="ScToSbf/Roll: missing"):
        load_ep(bad)
    bad.write_text("- just\n- a list\n")
    with pytest.raises(EngPktError, match="not an EP mapping"):
        load_ep(bad)
    with pytest.raises(EngPktError, match="unreadable"):
        load_ep(tmp_path / "absent.yaml")
