import json
from pathlib import Path

import pytest

from monitor.cli import main
from monitor.cli.registry import UsageError
from monitor.simulate.case import simulate_case
from tests.conftest import tree_with_truncated
from tests.invoke import run_crisgeo


def test_assess_writes_the_contract_json(cases, tmp_path, capsys, monkeypatch):
    """The command's own work (options, the table, the file) on the cached assessment of the case."""
    from monitor.assessment import assess

    out, _, result = cases.get()
    given = []
    monkeypatch.setattr(
        assess, "assess_plan", lambda case, cfg, progress, workers: given.append(case) or result
    )
    res = tmp_path / "r.json"
    assert main(["assess", str(out), "--out", str(res), "--workers", "1"]) == 0
    assert len(given) == 1 and len(given[0].cris) == 2  # the case's two granules, paired
    table = capsys.readouterr().out
    assert "FOR" in table and "d_beta" in table
    doc = json.loads(res.read_text())
    assert doc["satellite"] == "j01" and len(doc["fors"]) == 30 and len(doc["granules"]) == 2
    keys = {
        "scan_position",
        "for",  # the earlier name, kept for scripts
        "d_alpha_urad",
        "d_beta_urad",
        "sigma_alpha_urad",
        "sigma_beta_urad",
        "in_track_km",
        "cross_track_km",
        "total_km",
        "n_samples",
        "cost_min_k",
        "cost_zero_k",
        "flags",
    }
    assert keys <= set(doc["fors"][0])
    assert doc["start"] < doc["end"]


def test_missing_path_is_exit_2_with_one_line(tmp_path, capsys):
    assert main(["assess", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no such file" in err[0]


def test_only_corrupt_files_is_exit_2(tmp_path, capsys):
    (tmp_path / "GCRSO_j01_d20181022_t0023599_e0024297_b04790_c20181022005852745013_noac_ops.h5").write_text(
        "x"
    )
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
    printed = capsys.readouterr()
    skipped = [line for line in printed.out.splitlines() if line.startswith("skipped") and geo.name in line]
    assert len(skipped) == 1 and skipped[0].count(geo.name) == 1, skipped  # the file named once


def test_a_skipped_granule_leaves_no_numpy_warning(cases, tmp_path):
    """In its own process, as an operator runs it: no RuntimeWarning on stderr."""
    out, _, _ = cases.get()
    geo = sorted(out.glob("GCRSO_*.h5"))[1]
    work = tree_with_truncated(out, tmp_path / "case", geo)
    run = run_crisgeo("assess", work)
    assert run.returncode == 0, run.stderr
    assert "Warning" not in run.stderr, run.stderr


def test_simulate_cli_rejects_bad_profile(tmp_path, capsys):
    assert main(["simulate", "--out", str(tmp_path), "--profile", "nonsense", "--granules", "1"]) == 2
    assert "profile" in capsys.readouterr().err


def test_bench_prints_every_stage_and_the_assessment_memory():
    """`crisgeo bench` on a one-granule simulated case, in its own process so its memory is its own."""
    import re

    run = run_crisgeo("bench", "--granules", "1", "--workers", "1", "--kernel", "top-hat")
    assert run.returncode == 0, run.stderr
    out = run.stdout
    assert (
        "case: 1 CrIS granules (flat clouds), 1080 FOVs x 441 perturbations, cost regression, kernel top-hat"
        in out
    )
    cpu = float(re.search(r"^CPU: [0-9.]+ CPU-s, ([0-9.]+) CPU-s per CrIS granule", out, re.M).group(1))
    assert 0.5 < cpu < 200
    mb = float(re.search(r"^read: [0-9]+ MB, ([0-9.]+) MB per CrIS granule", out, re.M).group(1))
    assert 20 < mb < 2000  # one CrIS granule, its GEO and the VIIRS granules it reaches
    for stage in ("read", "geometry", "spectral", "collocation", "cost", "total"):
        secs, rate = re.search(rf"^  {stage} +([0-9.]+) s +([0-9.]+|inf) FOVs/s", out, re.M).groups()
        assert float(secs) > 0 or stage in ("spectral", "cost")
    peak = float(re.search(r"^peak memory: ([0-9]+) MB \(1 threads in one process\)$", out, re.M).group(1))
    assert 100 < peak < 3000
    assert "includes the simulation" not in out  # Linux resets the count after simulating


def test_bench_map_prints_the_mappings_cpu_per_band_with_the_reading_apart():
    import re

    run = run_crisgeo("bench", "--granules", "1", "--workers", "1", "--kernel", "top-hat", "--map")
    assert run.returncode == 0, run.stderr
    out = run.stdout
    assert "mapping onto I5, M13, M15, M16: 1 CrIS granules" in out
    for band in ("I5", "M13", "M15", "M16"):
        line = re.search(
            rf"^  {band} +read +([0-9.]+) CPU-s \(([0-9]+) MB, ([0-9.]+) MB per CrIS granule\) +"
            r"map +([0-9.]+)",
            out,
            re.M,
        )
        assert line is not None, (band, out)
        assert float(line.group(1)) > 0 and int(line.group(2)) > 0 and float(line.group(4)) > 0
    assert re.search(
        r"against the assessment's [0-9.]+ CPU-s: [0-9.]+ with the reading, [0-9.]+ beyond it", out
    )


def test_version_and_verbose_after_the_subcommand(capsys):

    r = run_crisgeo("--version")
    assert r.returncode == 0 and r.stdout.startswith("crisgeo ")
    from monitor.cli import build_parser

    args = build_parser().parse_args(["status", "-v", "--config", "x.yaml"])
    assert args.verbose is True and args.command == "status"
    assert build_parser().parse_args(["-v", "status"]).verbose is True
    assert build_parser().parse_args(["status"]).verbose is False


def _status_config(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
    )
    return cfg


def test_status_json_and_nagios_exit_codes(tmp_path, capsys, monkeypatch):
    import datetime as dt

    from alerts.rules import Finding
    from monitor.service.store.alert_state import AlertState
    from monitor.service.store.sqlite import Store

    cfg = _status_config(tmp_path)
    monkeypatch.setenv("CRISGEO_CONFIG", str(cfg))  # the default when --config is not given
    assert main(["status", "--json"]) == 3  # no store yet (the daemon makes it): UNKNOWN, and none made
    assert "no crisgeo store here yet" in json.loads(capsys.readouterr().out)["error"]
    assert not (tmp_path / "state" / "crisgeo.sqlite").exists()
    store = Store(tmp_path / "state" / "crisgeo.sqlite")
    assert main(["status", "--json", "--satellite", "j01"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["state"] == "OK" and doc["satellites"]["j01"]["last_run"] is None and doc["outbox"] == 0
    now = dt.datetime.now(dt.timezone.utc)
    AlertState(store).upsert(Finding("jump", "j01", "warning", "a step at FOR 21-30"), now, True)
    assert main(["status", "--json"]) == 1 and json.loads(capsys.readouterr().out)["state"] == "WARNING"
    assert main(["alerts", "list", "--json"]) == 0
    (alert,) = json.loads(capsys.readouterr().out)["alerts"]
    assert (alert["status"], alert["rule"], alert["satellite"], alert["severity"]) == (
        "firing",
        "jump",
        "j01",
        "warning",
    )
    assert (
        main(
            [
                "alerts",
                "silence",
                "--rule",
                "jump",
                "--until",
                (now + dt.timedelta(hours=2)).isoformat(),
                "--reason",
                "known step",
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert main(["alerts", "list", "--json"]) == 0
    view = json.loads(capsys.readouterr().out)
    assert view["alerts"][0]["status"] == "silenced" and view["silences"][0]["reason"] == "known step"
    assert main(["alerts"]) == 0 and "silenced  warning" in capsys.readouterr().out
    silence_id = view["silences"][0]["id"]
    assert main(["alerts", "unsilence", "--id", str(silence_id)]) == 0
    assert f"silence {silence_id} lifted" in capsys.readouterr().out
    assert main(["alerts", "list", "--json"]) == 0
    view = json.loads(capsys.readouterr().out)
    assert view["silences"] == [] and view["alerts"][0]["status"] == "firing"
    assert main(["alerts", "unsilence", "--id", str(silence_id)]) == 2  # no longer in force
    assert "no silence in force" in capsys.readouterr().err
    run = store.begin_run("j01", dt.date(2024, 6, 1))
    store.finish_run(run, "failed", "HTTP 503")
    assert main(["status"]) == 2
    out = capsys.readouterr().out
    first = out.splitlines()[0]
    assert first == "CRITICAL - j01: run of 2024-06-01 failed: HTTP 503; a step at FOR 21-30", out
    assert "warning jump" in out
    store.close()
    (tmp_path / "state" / "crisgeo.sqlite").write_bytes(b"garbage" * 100)
    assert main(["status", "--json"]) == 3 and json.loads(capsys.readouterr().out)["state"] == "UNKNOWN"
    monkeypatch.setenv("CRISGEO_CONFIG", str(tmp_path / "missing.yaml"))
    assert main(["status"]) == 3
    assert capsys.readouterr().out.startswith("UNKNOWN - ") and "missing.yaml: cannot read"


def test_run_logs_one_summary_line_per_day_in_json(cases, tmp_path):
    import os

    data, _, _ = cases.get()
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {data}}}\n"
        f"assessment: {{workers: 2}}\n"
    )
    r = run_crisgeo(
        "run",
        "--config",
        cfg,
        "--date",
        "2024-06-01",
        "--log-format",
        "json",
        env={k: v for k, v in os.environ.items() if k != "JOURNAL_STREAM"},
    )
    assert r.returncode == 0, r.stderr
    lines = [json.loads(line) for line in r.stderr.splitlines() if line.startswith("{")]
    assert lines and all({"time", "level", "logger", "message"} <= set(d) for d in lines)
    (summary,) = [d for d in lines if d["message"].startswith("run j01 2024-06-01: ok")]
    assert summary["satellite"] == "j01" and summary["day"] == "2024-06-01" and summary["priority"] == 6
    assert {"stage": "assess", "day": "2024-06-01"}.items() <= next(
        d for d in lines if "assessed granules" in d["message"]
    ).items()
    assert all("run_id" in d for d in lines if " after " in d["message"])
    summary = summary["message"]
    assert "granules listed 6, selected 2, assessed 2" in summary and "reliable FORs" in summary
    assert "worst" in summary and "stages list" in summary
    # not on a terminal: progress as log lines, the granules as they finish
    progress = [d["message"] for d in lines if " after " in d["message"]]
    assert any(m.startswith("j01 2024-06-01: fetched scenes: 2/2") for m in progress), progress
    assert any(m.startswith("j01 2024-06-01: assessed granules: 2/2") for m in progress), progress


def test_under_systemd_lines_carry_their_priority_and_no_second_timestamp(tmp_path):
    """The journal reads the <N> prefix as the line's priority (journalctl -p) and stamps the time."""
    import os

    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
    )
    import subprocess

    from monitor.service import logs
    from tests.invoke import CRISGEO, ROOT

    err = tmp_path / "stderr"
    with open(err, "w") as fh:  # the journal's stream: JOURNAL_STREAM names this stderr's device and inode
        st = os.fstat(fh.fileno())
        env = {**os.environ, "JOURNAL_STREAM": f"{st.st_dev}:{st.st_ino}"}
        argv = [*CRISGEO, "run", "--config", str(cfg), "--date", "2024-06-01"]
        r = subprocess.run(argv, stdout=subprocess.PIPE, stderr=fh, env=env, cwd=ROOT, timeout=300)
    assert r.returncode == 0, err.read_text()
    log = [line for line in err.read_text().splitlines() if line.strip()]
    prefixes = ("<6>INFO", "<4>WARNING", "<3>ERROR", "<7>DEBUG")
    assert all(line.split()[0] in prefixes for line in log), log
    # without journald listening (none here, or a stale socket) every line comes this way
    assert log or os.path.exists(logs.JOURNAL_SOCKET)


def test_a_line_the_journal_socket_refuses_goes_to_stderr_with_its_priority(tmp_path, capsys):
    import logging

    from monitor.service.logs import JournalHandler

    handler = JournalHandler(str(tmp_path / "no-journald"))
    record = logging.LogRecord("monitor.x", logging.ERROR, __file__, 1, "the day failed", None, None)
    handler.emit(record)
    handler.close()
    assert capsys.readouterr().err == "<3>ERROR monitor.x: the day failed\n"


@pytest.mark.parametrize(
    "extra,message",
    [
        (
            ["--since", "2024-03-05", "--until", "2024-03-01"],
            "--since 2024-03-05 is after --until 2024-03-01",
        ),
        (["--since", "2024-03-01", "--until", "2024-03-02", "--satellite", "npp"], "'npp' is not in"),
    ],
)
def test_reprocess_refuses_bad_input_in_one_line(tmp_path, capsys, extra, message):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(f"satellites: [j01]\nstate_dir: {tmp_path / 's'}\nsource: {{kind: simulated}}\n")
    assert main(["reprocess", "--config", str(cfg), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


REAL = sorted((Path(__file__).parents[1] / "data/real/collocations_j01_20181022").glob("*.npz"))


def test_assess_takes_the_configuration_the_daemon_assesses_with(tmp_path, capsys):
    """``assess --config`` assesses with the file's assessment section; an option overrides its key."""
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        "assessment: {cost: stdev, workers: 1}\n"
    )
    files = [str(p) for p in REAL[:4]]
    out = {name: tmp_path / f"{name}.json" for name in ("config", "flag", "default", "override")}
    assert main(["assess", "--config", str(cfg), *files, "--out", str(out["config"])]) == 0
    assert main(["assess", "--cost", "stdev", "--workers", "1", *files, "--out", str(out["flag"])]) == 0
    assert main(["assess", "--workers", "1", *files, "--out", str(out["default"])]) == 0
    override = ["assess", "--config", str(cfg), "--cost", "regression", *files, "--out", str(out["override"])]
    assert main(override) == 0
    capsys.readouterr()
    fors = {k: json.loads(p.read_text())["fors"] for k, p in out.items()}
    assert fors["config"] == fors["flag"]
    assert fors["override"] == fors["default"]
    assert fors["config"] != fors["default"]


def _subparsers():
    import argparse

    from monitor.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return parser, sub


def test_every_option_and_argument_has_help():
    import argparse

    parser, sub = _subparsers()
    missing = [
        (name, a.option_strings or a.dest)
        for name, sp in sub.choices.items()
        for a in sp._actions
        if not isinstance(a, argparse._HelpAction) and not a.help
    ]
    assert not missing


def test_every_subcommands_help_opens_with_what_it_does():
    _, sub = _subparsers()
    for name, sp in sub.choices.items():
        text = sp.format_help()
        opening = text.split("\n\n")[1]  # after the usage
        assert opening[0].isupper() and opening.rstrip().endswith("."), (name, opening)
        assert not opening.startswith(("positional", "options")), name


def test_satellite_takes_the_names_users_write(tmp_path):
    parser, _ = _subparsers()
    for given, short in (
        ("noaa20", "j01"),
        ("N20", "j01"),
        ("NOAA-21", "j02"),
        ("n21", "j02"),
        ("snpp", "npp"),
    ):
        args = parser.parse_args(["status", "--satellite", given])
        assert args.satellite == short, given
    with pytest.raises((UsageError, SystemExit)):
        parser.parse_args(["status", "--satellite", "noaa99"])


def test_help_lists_the_daily_job_first_and_the_exit_codes():
    parser, sub = _subparsers()
    names = list(sub.choices)
    assert names[:3] == ["run", "daemon", "status"]
    assert names.index("reprocess") < names.index("assess") < names.index("bench")
    text = parser.format_help()
    for code in ("0 success", "2 bad input", "75 another instance", "130 interrupted", "143 terminated"):
        assert code in text


def test_one_option_name_means_one_thing():
    """An option shared by commands has one meaning: the same destination and the same kind of value (the
    renamed ones keep their old name hidden, for scripts)."""
    import argparse

    _, sub = _subparsers()
    meaning: dict[str, set[str]] = {}
    for sp in sub.choices.values():
        for a in sp._actions:
            if a.help == argparse.SUPPRESS:
                continue
            for o in a.option_strings:
                meaning.setdefault(o, set()).add((a.dest, getattr(a.type, "__qualname__", str(a.type))))
    assert {o: m for o, m in meaning.items() if len(m) > 1 and o not in ("-h", "--help")} == {}
