"""The Grafana dashboards' specification thresholds come from the configuration."""

import json
from pathlib import Path

import pytest

from monitor.cli import main
from monitor.core.constants import SPEC_KM
from monitor.service.outputs.dashboards import with_specification

GRAFANA = Path(__file__).resolve().parents[3] / "configs" / "grafana"
DASHBOARDS = sorted(GRAFANA.glob("*.json"))


def _thresholds(dashboard):
    return [
        [s["value"] for s in p["fieldConfig"]["defaults"]["thresholds"]["steps"]]
        for p in dashboard["panels"]
        if p.get("fieldConfig", {}).get("defaults", {}).get("unit") == "lengthkm"
        and "thresholds" in p["fieldConfig"]["defaults"]
    ]


@pytest.mark.parametrize("path", DASHBOARDS, ids=lambda p: p.name)
def test_the_shipped_dashboard_is_its_rendering_at_the_default_specification(path):
    shipped = json.loads(path.read_text())
    assert with_specification(shipped, SPEC_KM) == shipped
    assert [None, -SPEC_KM, SPEC_KM] in _thresholds(shipped)


@pytest.mark.parametrize("path", DASHBOARDS, ids=lambda p: p.name)
def test_another_specification_moves_every_threshold_and_its_description(path):
    shipped = json.loads(path.read_text())
    other = with_specification(shipped, 2.0)
    spec_panels = [t for t in _thresholds(shipped) if t == [None, -SPEC_KM, SPEC_KM]]
    assert [t for t in _thresholds(other) if t == [None, -2.0, 2.0]] and len(spec_panels) == len(
        [t for t in _thresholds(other) if t == [None, -2.0, 2.0]]
    )
    text = json.dumps(other)
    assert "+-1.5 km specification" not in text and "+-2 km specification" in text
    assert shipped == json.loads(path.read_text())  # the input is left alone


def test_install_files_writes_the_dashboards_at_the_configured_specification(tmp_path, capsys):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        "alerts: {spec_km: 1.2}\n"
    )
    assert main(["install-files", str(tmp_path / "share"), "--config", str(cfg)]) == 0
    capsys.readouterr()
    written = json.loads((tmp_path / "share/configs/grafana/crisgeo-dashboard.json").read_text())
    assert [None, -1.2, 1.2] in _thresholds(written)
    assert [None, -SPEC_KM, SPEC_KM] not in _thresholds(written)
