"""What a newcomer meets first: every error path is one line with the right exit code, no empty product is
written silently, and commands that only read never create a store."""

import datetime as dt
import os

import pytest

from monitor.cli import main
from tests.invoke import ROOT, run_crisgeo


@pytest.fixture
def config_with_history(tmp_path):
    """A configuration of j01 and a store holding 12 simulated days from 2025-03-01."""
    from monitor.service.store.sqlite import Store
    from monitor.simulate.history import fill_store

    (tmp_path / "events.yaml").write_text("# the team's calendar\nevents:\n  # none yet\n  []\n")
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        f"alerts: {{events_file: {tmp_path / 'events.yaml'}}}\n"
    )
    with Store(tmp_path / "state" / "crisgeo.sqlite") as store:
        fill_store(store, ["j01"], dt.date(2025, 3, 1), 12, step_day=6, seed=3)
    return cfg


def _one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


@pytest.mark.parametrize(
    "extra,message",
    [
        (
            ["--out", "/nonexistent/dir/x.nc"],
            "--out /nonexistent/dir/x.nc: the folder /nonexistent/dir does not",
        ),
        (["--satellite", "npp"], "satellite 'npp' is not in the configuration (j01)"),
        (
            ["--since", "2025-03-09", "--until", "2025-03-02"],
            "--since 2025-03-09 is after --until 2025-03-02",
        ),
    ],
)
def test_export_refuses_in_one_line_and_writes_nothing(config_with_history, tmp_path, capsys, extra, message):
    out = tmp_path / "x.nc"
    argv = [
        "export",
        "--config",
        str(config_with_history),
        *(["--out", str(out)] if "--out" not in extra else []),
    ]
    assert main([*argv, *extra]) == 2
    line = _one_line(capsys)
    assert message in line and line.count(message.split(":")[0]) == 1  # its subject named once
    assert not out.exists() and not list(tmp_path.glob("*.part"))


def test_nothing_to_export_is_an_answer_not_bad_input(config_with_history, tmp_path, capsys):
    out = tmp_path / "x.nc"
    assert (
        main(["export", "--config", str(config_with_history), "--out", str(out), "--since", "2027-01-01"])
        == 0
    )
    line = _one_line(capsys)
    assert line.startswith("nothing to export: no results of j01 in 2027-01-01 .. the end")
    assert not out.exists() and not list(tmp_path.glob("*.part"))


def test_a_report_of_an_empty_period_leaves_the_live_report_untouched(config_with_history, tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["report", "--config", str(config_with_history), "--out", str(out)]) == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert any(p.suffix == ".png" for p in before)
    capsys.readouterr()
    assert (
        main(["report", "--config", str(config_with_history), "--out", str(out), "--since", "2030-01-01"])
        == 0
    )
    assert "is left as it was" in _one_line(capsys)
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_read_only_commands_never_create_a_store(tmp_path, capsys):
    from monitor import open_store
    from monitor.service.store.database import StoreError

    (tmp_path / "events.yaml").write_text("events: []\n")
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        f"alerts: {{events_file: {tmp_path / 'events.yaml'}}}\n"
    )
    assert main(["events", "list", "--config", str(cfg)]) == 0  # the calendar needs no store
    for argv in (
        ["alerts", "list"],
        ["export", "--out", str(tmp_path / "x.nc")],
        ["report"],
    ):
        assert main([argv[0], "--config", str(cfg), *argv[1:]]) == 1, argv
        assert "no crisgeo store here yet" in _one_line(capsys)
    with pytest.raises(StoreError, match="typo.sqlite: no crisgeo store here yet"):
        open_store(tmp_path / "typo.sqlite")
    assert not list(tmp_path.rglob("*.sqlite*"))


def test_events_add_keeps_the_calendars_comments(config_with_history, tmp_path, capsys):
    calendar = tmp_path / "events.yaml"
    calendar.write_text(
        "# the team's calendar: who changed what, when\nevents:\n"
        "  # the 2019 EP upload\n  - satellite: j01\n    time: 2019-01-02T00:00:00Z\n"
        "    instrument: cris\n    kind: ep_upload   # from the EP log\n    description: EP v115\n"
    )
    argv = ["events", "add", "--config", str(config_with_history), "--satellite", "j01"]
    argv += ["--time", "2025-03-04T00:00Z", "--instrument", "viirs", "--description", "LUT update"]
    assert main(argv) == 0
    text = calendar.read_text()
    for comment in ("# the team's calendar", "# the 2019 EP upload", "# from the EP log"):
        assert comment in text
    assert main(["events", "list", "--config", str(config_with_history)]) == 0
    out = capsys.readouterr().out
    assert "EP v115" in out and "LUT update" in out


def test_alerts_evaluate_prints_words_not_a_dict(config_with_history, capsys):
    assert main(["alerts", "evaluate", "--config", str(config_with_history)]) == 0
    out = capsys.readouterr().out.strip()
    assert out.startswith("queued ") and "sent " in out and "{" not in out


def test_help_has_no_markup():
    r = run_crisgeo("--help", timeout=60)
    assert r.returncode == 0 and "``" not in r.stdout and "The crisgeo command line." in r.stdout
    r = run_crisgeo("alerts", "--help", timeout=60)
    assert "unsilence" in r.stdout and "--id" in r.stdout and "the silence's number" in r.stdout


def test_the_cli_reference_is_generated_and_complete():

    from monitor.cli import COMMANDS

    r = run_crisgeo("--cli-reference", timeout=60)
    doc = (ROOT / "docs" / "cli.md").read_text()
    assert r.returncode == 0 and r.stdout == doc, "regenerate: crisgeo --cli-reference > docs/cli.md"
    assert all(f"## crisgeo {name}\n" in doc for name in COMMANDS)


@pytest.mark.parametrize(
    "options,message",
    [
        (["--steps", "40"], "assessment.half_steps: 40 with step_urad"),
        (["--steps", "0"], "assessment.half_steps: 0 is not within 1..40"),
        (["--kernel", "top-hat", "--workers", "100"], "assessment.workers: 100 is not within 1..64"),
    ],
)
def test_assess_options_are_checked_by_the_configuration_model(tmp_path, capsys, options, message):
    """crisgeo assess takes the assessment section's keys as options: the model checks them (the grid the
    compiled kernel takes included), one line, exit 2, before any granule is read."""
    assert main(["assess", str(tmp_path), *options]) == 2
    assert message in _one_line(capsys)


@pytest.mark.parametrize(
    "argv,message",
    [
        (
            ["bench", "--workers", "0"],
            "crisgeo bench: --workers: assessment.workers: 0 is not",
        ),
        (["bench", "--granules", "0"], "argument --granules: 0: at least 1"),
        (["simulate", "--out", "{tmp}/x", "--granules", "-3"], "argument --granules: -3: at least 1"),
        (["reprocess", "--since", "2024-06-01", "--processes", "0"], "argument --processes: 0: at least 1"),
        (
            ["reprocess", "--since", "2024-06-01", "--processes", "two"],
            "argument --processes: not a whole number",
        ),
        (["simulate", "--out", "{tmp}/x", "--seed", "-1"], "argument --seed: -1: at least 0"),
        (
            ["simulate", "--out", "{tmp}/x", "--footprint", "trapezoid:wide"],
            "--footprint: footprint 'trapezoid:wide': the stretch is S or AxB@DEG, not 'wide'",
        ),
        (
            ["simulate", "--out", "{tmp}/x", "--pass", "day", "--pass-lon", "nan"],
            "argument --pass-lon: nan: not a longitude within -180..180 deg",
        ),
        (
            ["fingerprint", "{tmp}", "--threshold-urad", "-5"],
            "fingerprint.threshold_urad: -5.0 is not within 0.1..10000",
        ),
    ],
)
def test_options_out_of_range_are_bad_input(tmp_path, argv, message):
    """A count of granules, processes or threads below one, a negative threshold: refused before anything
    runs, exit 2, the last line naming the option (they were taken before: zero granules simulated, a bench
    on "0 threads", a fingerprint flagging every FOR)."""
    run = run_crisgeo(*(a.format(tmp=tmp_path) for a in argv))
    assert run.returncode == 2
    assert message in run.stderr.strip().splitlines()[-1]
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    "argv,message",
    [
        (["run", "--date", "2010-01-01"], "--date 2010-01-01: before NOAA-20's launch on 2017-11-18"),
        (["run", "--date", "2030-01-01"], "--date 2030-01-01: after today"),
        (
            ["reprocess", "--since", "2017-11-01", "--until", "2017-12-01"],
            "--since 2017-11-01: before NOAA-20's launch",
        ),
        (["reprocess", "--since", "2025-01-01", "--until", "2099-01-01"], "--until 2099-01-01: after today"),
    ],
)
def test_a_day_outside_the_mission_is_bad_input_and_records_nothing(
    config_with_history, capsys, argv, message
):
    """A typo'd date: exit 2, one line, no run in the ledger and no alert (nothing sent, nothing queued)."""
    from monitor.service.store.alert_state import AlertState
    from monitor.service.store.sqlite import Store

    state = config_with_history.parent / "state"
    with Store(state / "crisgeo.sqlite", create=False) as store:
        before = store.runs("j01"), AlertState(store).all(), AlertState(store).deliveries()
    assert main([argv[0], "--config", str(config_with_history), *argv[1:]]) == 2
    assert message in _one_line(capsys)
    with Store(state / "crisgeo.sqlite", create=False) as store:
        assert (store.runs("j01"), AlertState(store).all(), AlertState(store).deliveries()) == before


def test_a_closed_pipe_keeps_the_computed_exit_status(config_with_history):
    """``crisgeo status | head -1``: a reader that closes the pipe early silences the output, not the
    Nagios code. The pipe here is closed before crisgeo writes anything (the worst case of head)."""
    import os
    import subprocess

    from tests.invoke import CRISGEO, ROOT

    argv = [*CRISGEO, "status", "--config", str(config_with_history)]
    expected = subprocess.run(argv, capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert expected.returncode in (0, 1, 2) and expected.stdout  # a computed state, printed
    read, write = os.pipe()
    os.close(read)  # nobody will read: every write fails with EPIPE
    try:
        closed = subprocess.run(argv, stdout=write, stderr=subprocess.PIPE, text=True, cwd=ROOT, timeout=120)
    finally:
        os.close(write)
    assert closed.returncode == expected.returncode, closed.stderr
    assert "BrokenPipeError" not in closed.stderr and "Traceback" not in closed.stderr


def test_check_config_speaks_to_the_operators_habits(tmp_path):
    """An unquoted 3:30 (YAML's base-60 number 210) is told to be quoted; a folder given as the file is
    named once; unset secrets are warned of on stderr, one line per variable, and the file stays valid."""
    base = f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: simulated}}\n"
    (tmp_path / "a.yaml").write_text(base + "schedule: {time_utc: 3:30}\n")
    r = run_crisgeo("check-config", "--config", tmp_path / "a.yaml")
    assert r.returncode == 2 and "time_utc: 210 is not HH:MM" in r.stderr and "quote it, '03:30'" in r.stderr
    r = run_crisgeo("check-config", "--config", f"{tmp_path}/")
    assert r.returncode == 2 and r.stderr.count(str(tmp_path)) == 1, r.stderr
    (tmp_path / "b.yaml").write_text(
        base + "alerts:\n  slack: {webhook_env: CRISGEO_TEST_UNSET_HOOK}\n"
        "  email: {host: localhost, sender: a@b.c, to: [c@d.e], password_env: CRISGEO_TEST_SET_PW}\n"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith("CRISGEO_TEST_")}
    r = run_crisgeo("check-config", "--config", tmp_path / "b.yaml", env={**env, "CRISGEO_TEST_SET_PW": "x"})
    assert r.returncode == 0, r.stderr
    assert r.stderr.splitlines() == [
        "crisgeo check-config: warning: alerts.slack.webhook_env: CRISGEO_TEST_UNSET_HOOK is not set"
    ]


@pytest.mark.parametrize(
    "argv,message",
    [
        (["--satellite", "noaa99"], "argument --satellite: 'noaa99' is not a satellite"),
        (["--bogus"], "unrecognized arguments: --bogus"),
        (["-w", "abc"], "not a threshold range"),
        (["-t", "0.000001"], "no answer within 1e-06 s (-t)"),
    ],
)
def test_status_usage_errors_and_its_timeout_are_nagios_unknown(config_with_history, capsys, argv, message):
    """A Nagios plugin's usage error or expired timeout is UNKNOWN (3), one line on stdout; the same typo in
    another command stays bad input (2)."""
    code = main(["status", "--config", str(config_with_history), *argv])
    out = capsys.readouterr().out.splitlines()
    assert code == 3 and len(out) == 1 and out[0].startswith("UNKNOWN - ") and message in out[0], out
    assert main(["report", "--config", str(config_with_history), "--satellite", "n21"]) == 2


def test_the_demos_calendar_edits_stay_in_the_demos_state(tmp_path, capsys):
    """`crisgeo events add` on the demo writes the demo's own calendar under its state, never the
    calendar the project ships."""
    shipped = ROOT / "configs" / "events.yaml"
    before = shipped.read_bytes()
    (tmp_path / "configs").mkdir()
    demo = tmp_path / "configs" / "demo.yaml"
    demo.write_text((ROOT / "configs" / "demo.yaml").read_text())
    argv = ["events", "add", "--config", str(demo), "--satellite", "noaa20", "--time", "2026-01-01T00:00Z"]
    assert main([*argv, "--instrument", "cris", "--description", "a test EP"]) == 0
    assert "a test EP" in (tmp_path / "demo-state" / "events.yaml").read_text()
    assert shipped.read_bytes() == before
