"""The wheel carries what a deployment needs: built with pip, installed into a fresh venv, copied out."""

import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import yaml

from tests.invoke import ROOT


def test_wheel_installs_the_shipped_files(tmp_path):
    wheels = tmp_path / "wheels"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            str(ROOT),
            "-w",
            str(wheels),
        ],
        check=True,
        cwd=tmp_path,
        capture_output=True,
    )
    (wheel,) = wheels.glob("crisgeo_monitor-*.whl")
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    py = env_dir / "bin" / "python"
    subprocess.run(
        [py, "-m", "pip", "install", "-q", "--no-deps", "--no-index", str(wheel)],
        check=True,
        capture_output=True,
    )
    # the dependencies (numpy, h5py, ...) are borrowed from the test environment by a path line, so no
    # index is needed; the package itself must come from the wheel
    site = subprocess.run(
        [py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    deps = Path(sysconfig.get_paths()["purelib"])
    Path(site, "zz_test_dependencies.pth").write_text(f"{deps}\n")
    where = subprocess.run(
        [py, "-c", "import monitor; print(monitor.__file__, monitor.__version__)"],
        check=True,
        capture_output=True,
        text=True,
        cwd=tmp_path,
    ).stdout
    assert where.startswith(site) and "unknown" not in where, where
    crisgeo = env_dir / "bin" / "crisgeo"
    share = tmp_path / "share"
    r = subprocess.run([crisgeo, "install-files", str(share)], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    for rel in (
        "configs/monitor.yaml",
        "configs/events.yaml",
        "configs/grafana/crisgeo-dashboard.json",
        "configs/grafana/crisgeo-prometheus-dashboard.json",
        "configs/grafana/provisioning/datasources/crisgeo.yaml",
        "configs/ep/j01_nominal.yaml",
        "configs/prometheus/crisgeo-rules.yml",
        "systemd/crisgeo.service",
        "systemd/crisgeo.logrotate",
        "README.md",
        "docs/configuration.md",
    ):
        assert (share / rel).read_bytes() == (ROOT / rel).read_bytes(), rel
    assert (
        "Documentation=file:///opt/crisgeo/share/README.md" in (share / "systemd/crisgeo.service").read_text()
    )
    # the example configuration is valid where it lands, next to its events calendar
    assert yaml.safe_load((share / "configs/monitor.yaml").read_text())["satellites"]
    # an operator's edited file is kept unless --force
    (share / "configs/monitor.yaml").write_text("# edited\n")
    r = subprocess.run([crisgeo, "install-files", str(share)], capture_output=True, text=True, cwd=tmp_path)
    assert "kept  " + str(share / "configs/monitor.yaml") in r.stdout
    assert (share / "configs/monitor.yaml").read_text() == "# edited\n"
    subprocess.run(
        [crisgeo, "install-files", "--force", str(share)], check=True, capture_output=True, cwd=tmp_path
    )
    assert (share / "configs/monitor.yaml").read_bytes() == (ROOT / "configs/monitor.yaml").read_bytes()
    # the documented importlib.resources place
    r = subprocess.run(
        [
            py,
            "-c",
            "from importlib.resources import files; "
            "print((files('monitor') / 'shipped' / 'systemd' / 'crisgeo.service').read_text())",
        ],
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    )
    assert "Type=notify" in r.stdout
