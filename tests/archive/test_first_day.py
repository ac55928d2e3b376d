"""docs/operations.md's "A first real day", run as written: its configuration (plus the endpoint of an S3
server on loopback holding simulated granules in NODD's layout, since NODD cannot be reached here) and its
commands, in a scratch folder."""

import os
import re
import subprocess

import pytest

from benchmarks.servers import S3Server, nodd_key
from tests.invoke import CRISGEO, ROOT

pytestmark = pytest.mark.servers  # starts real servers (see pyproject markers)


def _recipe() -> tuple[str, list[str]]:
    """The recipe's configuration file and its crisgeo commands."""
    text = (ROOT / "docs" / "operations.md").read_text()
    block = text.split("### A first real day", 1)[1]
    lines = [line[4:] for line in block.splitlines() if line.startswith("    ")]
    start = next(i for i, line in enumerate(lines) if line.startswith("cat > first-day.yaml <<'EOF'"))
    end = lines.index("EOF", start)
    commands = [line for line in lines[end + 1 :] if line.startswith("crisgeo ")]
    return "\n".join(lines[start + 1 : end]) + "\n", commands


def test_the_first_real_day_recipe_runs_as_written(cases, tmp_path):
    data, _, _ = cases.get()
    bucket = tmp_path / "s3"
    for f in data.glob("*.h5"):
        key = bucket / "noaa-nesdis-n20-pds" / nodd_key(f.name)
        key.parent.mkdir(parents=True, exist_ok=True)
        os.link(f, key)
    config, commands = _recipe()
    assert commands == [
        "crisgeo run --config first-day.yaml --date 2024-06-01",
        "crisgeo status --config first-day.yaml",
        "crisgeo report --config first-day.yaml",
    ]
    scratch = tmp_path / "crisgeo-first-day"
    scratch.mkdir()
    with S3Server(bucket) as s3:
        endpoint = f"  endpoint: {s3.url}/{{bucket}}  # the test's S3 server standing in for NODD\n"
        (scratch / "first-day.yaml").write_text(re.sub(r"(  kind: nodd\n)", r"\1" + endpoint, config))
        outputs = [
            subprocess.run(
                [*CRISGEO, *c.split()[1:]], cwd=scratch, capture_output=True, text=True, timeout=600
            )
            for c in commands
        ]
    run, status, report = outputs
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("j01 2024-06-01: ok") and "FOR  d_alpha" in run.stdout
    assert "granules listed" in run.stderr and "MB downloaded" in run.stderr
    assert status.returncode in (0, 1, 2) and status.stdout.split(" - ")[0] in ("OK", "WARNING", "CRITICAL")
    assert "latest results: 2024-06-01" in status.stdout
    assert report.returncode == 0, report.stderr
    assert (scratch / "report" / "j01" / "index.html").exists() and (scratch / "crisgeo.sqlite").exists()
    assert not list(tmp_path.glob("*.sqlite"))  # everything in the scratch folder
