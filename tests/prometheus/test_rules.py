"""The shipped Prometheus alerting rules: valid for promtool, and firing when they should (promtool's unit
tests, with the series a dead, a stuck and a healthy daemon would expose)."""

import subprocess
from pathlib import Path

import pytest

from benchmarks.servers import require

pytestmark = pytest.mark.servers  # starts real servers, daemons or tools (see pyproject markers)

ROOT = Path(__file__).resolve().parents[2]
RULES = ROOT / "configs" / "prometheus" / "crisgeo-rules.yml"


def test_rules_check():
    r = subprocess.run([require("promtool"), "check", "rules", str(RULES)], capture_output=True, text=True)
    assert r.returncode == 0 and "SUCCESS: 5 rules found" in r.stdout, r.stdout + r.stderr
    # the service's own alerts go out once, by the service (or through Alertmanager): no rule repeats them
    assert "crisgeo_alerts_firing" not in RULES.read_text()


def test_rules_fire_as_documented(tmp_path):
    spec = (Path(__file__).parent / "rules_test.yml").read_text().replace("RULES", str(RULES))
    (tmp_path / "rules_test.yml").write_text(spec)
    r = subprocess.run(
        [require("promtool"), "test", "rules", str(tmp_path / "rules_test.yml")],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0 and "SUCCESS" in r.stdout, r.stdout + r.stderr
