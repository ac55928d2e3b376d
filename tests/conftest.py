"""Shared fixtures: real NOAA-20 GEO granules shipped with the tests, and small simulated cases."""

from __future__ import annotations

import fcntl
import json
import logging
import os
import pickle
from pathlib import Path

import numpy as np
import pytest

from monitor.assessment.assess import assess_paths
from monitor.config.assessment import AssessmentConfig
from monitor.sdr.engpkt import load_ep
from monitor.sdr.pairing import plan
from monitor.simulate.case import simulate_case

REAL_DIR = Path(__file__).parent / "data" / "real"
EP_CONFIGS = Path(__file__).resolve().parent.parent / "configs" / "ep"


@pytest.fixture(autouse=True)
def _root_logging_restored():
    """A command run in a test (``main``: :func:`monitor.service.logs.setup`) points the root logger at the
    test's captured stderr; a server thread that logs after the test (aiosmtpd's ``mail.log`` as it stops)
    would then write to a closed stream. The root logger's handlers and level are put back after each
    test."""
    root = logging.getLogger()
    handlers, level = list(root.handlers), root.level
    yield
    for h in [h for h in root.handlers if h not in handlers]:
        root.removeHandler(h)
    for h in handlers:
        if h not in root.handlers:
            root.addHandler(h)
    root.setLevel(level)


@pytest.fixture(scope="session")
def nominal_ep():
    """The nominal NOAA-20 EP (V115) of configs/ep."""
    return load_ep(EP_CONFIGS / "j01_nominal.yaml")


@pytest.fixture(scope="session")
def error_ep():
    """V115 with the paper-like scene-mirror error of configs/ep."""
    return load_ep(EP_CONFIGS / "j01_paper_ssm_error.yaml")


@pytest.fixture(scope="session")
def real_geo_files():
    files = sorted(REAL_DIR.glob("GCRSO_j01_*.h5"))
    assert len(files) == 10
    return files


class Clock:
    """A monotonic clock the test turns by hand: call it for the time, set ``t`` to move it."""

    def __init__(self, t: float = 1000.0):
        self.t = t

    def __call__(self) -> float:
        return self.t


class CaseCache:
    """Simulated cases and their assessments, made once per test run: the xdist workers share them (the
    first to ask makes a case under a file lock, the others wait for it and read it back)."""

    def __init__(self, factory):
        base = factory.getbasetemp()
        self.root = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "cases"
        self.root.mkdir(exist_ok=True)
        self.cases = {}

    def get(self, profile="paper", seed=1, granules=2, satellite="j01", clouds="ground", bands=("I5",)):
        """(directory, truth, result) of a case; with bands beyond I5 the result is None (not assessed)."""
        key = (profile, seed, granules, satellite, clouds, tuple(bands))
        if key not in self.cases:
            tag = "" if tuple(bands) == ("I5",) else "_" + "-".join(bands)
            name = f"case_{profile}_{seed}_{granules}_{satellite}_{clouds}{tag}"
            out, made = self.root / name, self.root / f"{name}.pickle"
            with open(self.root / f"{name}.lock", "w") as lock:
                fcntl.flock(lock, fcntl.LOCK_EX)
                if not made.exists():
                    truth = simulate_case(
                        out,
                        satellite=satellite,
                        granules=granules,
                        profile=profile,
                        seed=seed,
                        cloud_heights=clouds,
                        viirs_bands=tuple(bands),
                    )
                    result = assess_paths([out], AssessmentConfig()) if not tag else None
                    made.with_suffix(".part").write_bytes(pickle.dumps((truth, result)))
                    made.with_suffix(".part").rename(made)
            self.cases[key] = (out, *pickle.loads(made.read_bytes()))
        return self.cases[key]


@pytest.fixture(scope="session")
def cases(tmp_path_factory):
    return CaseCache(tmp_path_factory)


@pytest.fixture(scope="module")
def case_plan(cases):
    """The plan (paired CrIS and VIIRS granules) of the default simulated case."""
    out, _, _ = cases.get()
    return plan([out])


def truth_arrays(truth):
    return (
        np.array([f["d_alpha_urad"] for f in truth["fors"]]),
        np.array([f["d_beta_urad"] for f in truth["fors"]]),
    )


def load_truth(case_dir):
    return json.loads((Path(case_dir) / "truth.json").read_text())


def tree_with_truncated(src, dst, victim, keep_bytes=5000):
    """*dst*: links to every granule of *src*, except *victim* (a path in *src*), copied truncated."""
    dst.mkdir()
    for f in src.glob("*.h5"):
        if f.name == victim.name:
            (dst / f.name).write_bytes(f.read_bytes()[:keep_bytes])
        else:
            (dst / f.name).symlink_to(f)
    return dst
