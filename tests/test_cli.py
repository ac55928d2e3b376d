import json

import pytest

from monitor.cli import main
from tests.conftest import tree_with_truncated
from monitor.simulate.case import simulate_case


def test_assess_writes_the_contract_json(cases, tmp_path, capsys):
    out, _, _ = cases.get()
    res = tmp_path / "r.json"
    assert main(["assess", str(out), "--out", str(res)]) == 0
    table = capsys.readouterr().out
    assert "FOR" in table and "d_beta" in table
    doc = json.loads(res.read_text())
    assert doc["satellite"] == "j01" and len(doc["fors"]) == 30 and len(doc["granules"]) == 2
    keys = {"for", "d_alpha_urad", "d_beta_urad", "sigma_alpha_urad", "sigma_beta_urad", "in_track_km",
            "cross_track_km", "total_km", "n_samples", "cost_min_k", "cost_zero_k", "flags"}
    assert keys <= set(doc["fors"][0])
    assert doc["start"] < doc["end"]


def test_missing_path_is_exit_2_with_one_line(tmp_path, capsys):
    assert main(["assess", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no such file" in err[0]


def test_only_corrupt_files_is_exit_2(tmp_path, capsys):
    (tmp_path / "GCRSO_j01_d20181022_t0023599_e0024297_b04790_c20181022005852745013_noac_ops.h5").write_text("x")
    assert main(["assess", str(tmp_path)]) == 2
    assert "not a readable HDF5 file" in capsys.readouterr().err


def test_mixed_satellites_is_exit_2(real_geo_files, tmp_path, capsys):
    simulate_case(tmp_path / "npp", satellite="npp", granules=1, profile="zero", viirs=False)
    assert main(["assess", str(real_geo_files[0]), str(tmp_path / "npp")]) == 2
    assert "mixed satellites" in capsys.readouterr().err


def test_cris_without_viirs_in_time_is_exit_2(tmp_path, capsys):
    simulate_case(tmp_path, granules=1, profile="zero", viirs=False)
    assert main(["assess", str(tmp_path)]) == 2
    assert "no VIIRS I5 granule covers" in capsys.readouterr().err


def test_corrupt_granule_is_skipped_and_recorded(cases, tmp_path, capsys):
    out, _, _ = cases.get()
    geo = sorted(out.glob("GCRSO_*.h5"))[1]
    work = tree_with_truncated(out, tmp_path / "case", geo)
    res = tmp_path / "r.json"
    assert main(["assess", str(work), "--out", str(res)]) == 0
    doc = json.loads(res.read_text())
    assert len(doc["granules"]) == 1
    reasons = " ".join(s["reason"] for s in doc["skipped"])
    assert geo.name in " ".join(s["item"] for s in doc["skipped"]) and "HDF5" in reasons
    assert "skipped" in capsys.readouterr().out


def test_simulate_cli_rejects_bad_profile(tmp_path, capsys):
    assert main(["simulate", "--out", str(tmp_path), "--profile", "nonsense", "--granules", "1"]) == 2
    assert "profile" in capsys.readouterr().err


def test_bench_prints_every_stage_and_the_assessment_memory():
    """`crisgeo bench` on a one-granule simulated case, in its own process so its memory is its own."""
    import re
    import subprocess
    import sys
    run = subprocess.run([sys.executable, "-c", "from monitor.cli import main; raise SystemExit(main("
                          "['bench', '--granules', '1', '--workers', '1']))"],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    out = run.stdout
    assert "case: 1 CrIS granules, 1080 FOVs x 441 perturbations" in out
    for stage in ("read", "geometry", "spectral", "collocation", "cost", "total"):
        secs, rate = re.search(rf"^  {stage} +([0-9.]+) s +([0-9.]+|inf) FOVs/s", out, re.M).groups()
        assert float(secs) > 0 or stage in ("spectral", "cost")
    peak = float(re.search(r"^peak memory: ([0-9]+) MB$", out, re.M).group(1))
    assert 100 < peak < 3000
    assert "includes the simulation" not in out  # Linux resets the count after simulating
