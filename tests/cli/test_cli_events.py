"""``crisgeo events``: the calendar listed whatever satellites the configuration watches, filtered by
--satellite; an exact duplicate refused in one line, the file untouched."""

import shutil

from tests.invoke import ROOT, run_crisgeo


def _config(tmp_path):
    shutil.copy(ROOT / "configs" / "events.yaml", tmp_path / "events.yaml")
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        f"alerts: {{events_file: {tmp_path / 'events.yaml'}}}\n"
    )
    return cfg


def test_list_shows_the_calendar_of_every_satellite_and_filters(tmp_path):
    cfg = _config(tmp_path)
    every = run_crisgeo("events", "list", "--config", cfg)
    assert every.returncode == 0, every.stderr
    npp = [line for line in every.stdout.splitlines() if line.startswith("npp ")]
    assert len(npp) == 3 and "engineering packet v36" in npp[-1]  # the shipped S-NPP history, in time order
    only = run_crisgeo("events", "list", "--config", cfg, "--satellite", "j01")
    assert only.returncode == 0 and not [line for line in only.stdout.splitlines() if line.startswith("npp ")]


def test_add_refuses_an_exact_duplicate(tmp_path):
    cfg = _config(tmp_path)
    add = ["events", "add", "--config", cfg, "--satellite", "j01", "--time", "2026-01-05T00:00Z"]
    add += ["--instrument", "cris", "--kind", "ep_upload", "--description", "EP v116"]
    first = run_crisgeo(*add)
    assert first.returncode == 0, first.stderr
    before = (tmp_path / "events.yaml").read_text()
    again = run_crisgeo(*add)
    assert again.returncode == 2 and len(again.stderr.strip().splitlines()) == 1, again.stderr
    assert "already in the calendar: CrIS ep_upload on 2026-01-05 00:00 UTC" in again.stderr
    assert (tmp_path / "events.yaml").read_text() == before
    listed = run_crisgeo("events", "--config", cfg, "--satellite", "j01").stdout
    assert listed.count("EP v116") == 1


def test_effects_measures_what_each_change_did(tmp_path):
    """The history of tests/alerts/test_effects.py in the configured store, the upload in the calendar: the
    table per FOR with the EPs' prediction; before any run, one line saying there is no store."""
    from tests.alerts.test_effects import _history

    cfg = _config(tmp_path)
    absent = run_crisgeo("events", "effects", "--config", cfg)
    assert absent.returncode == 2 and "no store yet" in absent.stderr
    (tmp_path / "state").mkdir()
    store, _, _, _ = _history(tmp_path / "state")
    store.close()
    (tmp_path / "state" / "s.sqlite").rename(tmp_path / "state" / "crisgeo.sqlite")
    (tmp_path / "events.yaml").write_text(
        "events:\n  - {satellite: j01, time: '2024-04-10T12:00:00Z', instrument: cris, kind: ep_upload, "
        "description: EP V116}\n"
    )
    done = run_crisgeo("events", "effects", "--config", cfg, "--satellite", "j01")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("j01 2024-04-10: CrIS ep_upload") and "EP V116" in lines[0]
    assert "V115" in lines[1] and "V116" in lines[1] and "chi2" in lines[1]
    rows = [line.split() for line in lines if line.strip().split(" ")[0].isdigit()]
    assert len(rows) == 60  # every FOR, both directions, through the end of the history
    moved = [r for r in rows if r[1] == "in-track" and 11 <= int(r[0]) <= 20]
    assert all(r[-3] == "yes" and r[-2] == "-80.0" for r in moved)
