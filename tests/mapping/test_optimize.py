"""The optimiser (equations 19-23) on exact offsets, flagged FORs, wrong satellites; the CLI."""

import dataclasses
import json

import numpy as np
import pytest

from monitor.cli import main
from monitor.core.errors import DataError
from monitor.core.result import AssessmentResult, ForOffset, GranuleInfo
from monitor.mapping.optimize import optimize
from monitor.sdr.engpkt import load_ep
from monitor.simulate.case import ep_offsets_urad


def _result(d_alpha, d_beta, satellite="j01", flags=None):
    flags = flags or {}
    fors = [
        ForOffset(
            k + 1,
            float(a),
            float(b),
            5.0,
            5.0,
            0.0,
            0.0,
            0.0,
            0.01,
            0.01,
            100,
            1.0,
            2.0,
            tuple(flags.get(k + 1, ())),
        )
        for k, (a, b) in enumerate(zip(d_alpha, d_beta, strict=True))
    ]
    return AssessmentResult(
        satellite,
        "2024-06-01T12:00:00",
        "2024-06-01T12:07:28",
        fors,
        granules=[GranuleInfo(g, "", "", "", "", [], 0, 0) for g in ("J01001", "J01002")],
    )


def test_exact_offsets_recover_the_true_mirror_angles(nominal_ep, error_ep):
    d_alpha, d_beta = ep_offsets_urad(error_ep, nominal_ep)
    opt = optimize(_result(d_alpha, d_beta), nominal_ep)
    assert np.max(np.abs(opt.ep.ssm_crosstrack_roll_rad - error_ep.ssm_crosstrack_roll_rad)) < 1e-9
    assert np.max(np.abs(opt.ep.ssm_intrack_pitch_rad - error_ep.ssm_intrack_pitch_rad)) < 1e-9
    assert opt.ep.provenance["derived_from"] == "V115" and opt.ep.provenance["assessment"]["n_granules"] == 2
    assert not opt.kept
    row = opt.rows[29]
    assert row.d_roll_urad == pytest.approx(-1000.0, abs=1e-3)


def test_flagged_and_missing_fors_keep_their_angles(nominal_ep, error_ep):
    d_alpha, d_beta = ep_offsets_urad(error_ep, nominal_ep)
    d_alpha[4] = np.nan
    opt = optimize(_result(d_alpha, d_beta, flags={30: ("edge",), 12: ("flat", "uncertain")}), nominal_ep)
    kept = {r.for_index: r.kept for r in opt.kept}
    assert kept == {5: "no offset (NaN)", 12: "flagged flat+uncertain", 30: "flagged edge"}
    for k in (4, 11, 29):
        assert opt.ep.ssm_crosstrack_roll_rad[k] == nominal_ep.ssm_crosstrack_roll_rad[k]
        assert opt.ep.ssm_intrack_pitch_rad[k] == nominal_ep.ssm_intrack_pitch_rad[k]
    assert opt.ep.ssm_crosstrack_roll_rad[28] != nominal_ep.ssm_crosstrack_roll_rad[28]
    assert "3 FOR(s) kept their angles" in opt.table() and "FOR 30 (flagged edge)" in opt.table()
    assert opt.ep.provenance["fors_kept"]["30"] == "flagged edge"


def test_wrong_satellite_or_incomplete_result_is_refused(nominal_ep):
    with pytest.raises(DataError, match="is for npp, the EP V115 for j01"):
        optimize(_result(np.zeros(30), np.zeros(30), satellite="npp"), nominal_ep)
    short = _result(np.zeros(30), np.zeros(30))
    short = dataclasses.replace(short, fors=short.fors[:29])
    with pytest.raises(DataError, match="needs FORs 1..30"):
        optimize(short, nominal_ep)


def test_cli_optimize_writes_the_ep_in_the_input_format(tmp_path, nominal_ep, error_ep, capsys):
    d_alpha, d_beta = ep_offsets_urad(error_ep, nominal_ep)
    res = tmp_path / "result.json"
    res.write_text(_result(d_alpha, d_beta).to_json())
    from monitor.sdr.engpkt import packaged_path

    assert (
        main(
            [
                "optimize",
                str(res),
                "--ep",
                str(packaged_path("j01")),
                "--out",
                str(tmp_path / "new.xml"),
                "--table-json",
                str(tmp_path / "table.json"),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "ActualCrosstrackAngleRoll" in out and "wrote" in out
    new = load_ep(tmp_path / "new.xml")
    assert abs(new.ssm_crosstrack_roll_rad[29] - error_ep.ssm_crosstrack_roll_rad[29]) <= 0.5e-6
    table = json.loads((tmp_path / "table.json").read_text())
    assert table[29]["d_roll_urad"] == pytest.approx(-1000.0, abs=0.01)


def test_cli_optimize_bad_inputs(tmp_path, capsys):
    from monitor.sdr.engpkt import packaged_path

    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert (
        main(["optimize", str(bad), "--ep", str(packaged_path("j01")), "--out", str(tmp_path / "x.xml")]) == 2
    )
    assert "not an assessment result" in capsys.readouterr().err
    res = tmp_path / "npp.json"
    res.write_text(_result(np.zeros(30), np.zeros(30), satellite="npp").to_json())
    assert (
        main(["optimize", str(res), "--ep", str(packaged_path("j01")), "--out", str(tmp_path / "x.xml")]) == 2
    )
    assert "is for npp" in capsys.readouterr().err
    assert not (tmp_path / "x.xml").exists()


def test_cli_simulate_in_ep_terms_checks_its_inputs(tmp_path, capsys):
    from monitor.sdr.engpkt import packaged_path

    v115, v37 = str(packaged_path("j01")), str(packaged_path("npp"))
    assert main(["simulate", "--out", str(tmp_path / "a"), "--true-ep", v115]) == 2
    assert "go together" in capsys.readouterr().err
    assert main(["simulate", "--out", str(tmp_path / "b"), "--true-ep", v115, "--ground-ep", v37]) == 2
    assert "EP V37 is for npp, the simulation for j01" in capsys.readouterr().err
