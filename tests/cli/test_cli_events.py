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
