"""A FOR's record built once, from its parts, with its sigmas final where they are computed."""

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import N_FOR, URAD
from monitor.core.result import FLAG_UNCERTAIN, MEASURED_FIELDS
from monitor.estimation import offsets
from monitor.estimation.intercal import Intercalibration
from monitor.instrument import footprint
from tests.estimation.test_estimate import STEP_RAD, _samples

ROOT = Path(__file__).resolve().parents[2]
STEP_URAD = STEP_RAD * 1e6


def test_every_part_lands_in_its_field():
    cal = Intercalibration(0.1, 0.01, 2.0, 0.2, 0.3, 0.03)
    f = offsets.for_offset(
        7, 120, offsets.Pair(10.0, -20.0, 3.0, 4.0), offsets.Ground(0.01, -0.02, 0.002, 0.003), 0.5, 0.9, cal,
        offsets.Widths(16000.0, 80.0, 24000.0, 90.0), offsets.Pair(-150.0, 5.0, 40.0, 9.0), 180.0, 2.5,
        ["flat", "flat"],
    )  # fmt: skip
    assert (f.for_index, f.n_samples, f.d_alpha_urad, f.d_beta_urad) == (7, 120, 10.0, -20.0)
    assert (f.sigma_alpha_urad, f.sigma_beta_urad, f.cost_min_k, f.cost_zero_k) == (3.0, 4.0, 0.5, 0.9)
    assert f.total_km == pytest.approx(np.hypot(0.01, 0.02)) and f.sigma_cross_track_km == 0.003
    assert (f.bias_k, f.sigma_gain_pct, f.sigma_curvature_k) == (0.1, 0.2, 0.03)
    assert (f.response_width_10_urad, f.sigma_response_width_50_urad) == (24000.0, 80.0)
    assert (f.fov_rows_alpha_urad, f.sigma_fov_rows_beta_urad) == (-150.0, 9.0)
    assert (f.parallax_m_per_k, f.parallax_height_km, f.flags) == (180.0, 2.5, ("flat",))


def _jacobian(k, d_alpha_rad, d_beta_rad):
    """A ground with 1 km per mrad in-track and 2 km per mrad cross-track."""
    jac = np.diag([1e3, 2e3])
    return d_alpha_rad * 1e3, d_beta_rad * 2e3, jac


def test_the_lifts_spread_is_in_every_sigma_and_the_km_sigmas_follow():
    """The spread the day's lift adds is in the FOR's and the rows' sigmas where they are computed, and the
    km sigmas and the uncertainty flag are derived from those final sigmas."""
    s = _samples(footprint.super_gaussian(), n=160)
    cfg = AssessmentConfig(min_samples=10, max_sigma_urad=100.0)
    (bare,) = offsets.day_offsets([s], cfg, STEP_URAD, _jacobian).fors
    spread = np.zeros((4, N_FOR))
    spread[:, 0] = (300.0, 40.0, 50.0, 60.0)
    lift = offsets.DayLift(150.0, np.full(N_FOR, 2.0), *spread)
    (lifted,) = offsets.day_offsets([s], cfg, STEP_URAD, _jacobian, lift=lift).fors
    assert lifted.sigma_alpha_urad == pytest.approx(np.hypot(bare.sigma_alpha_urad, 300.0))
    assert lifted.sigma_beta_urad == pytest.approx(np.hypot(bare.sigma_beta_urad, 40.0))
    # these samples carry no FOV rows: nothing measured stays NaN, whatever the lift adds
    assert np.isnan(bare.sigma_fov_rows_alpha_urad) and np.isnan(lifted.sigma_fov_rows_alpha_urad)
    assert lifted.sigma_in_track_km == pytest.approx(lifted.sigma_alpha_urad * URAD * 1e3)
    assert lifted.sigma_cross_track_km == pytest.approx(lifted.sigma_beta_urad * URAD * 2e3)
    assert FLAG_UNCERTAIN in lifted.flags and FLAG_UNCERTAIN not in bare.flags
    assert (lifted.parallax_m_per_k, lifted.parallax_height_km) == (150.0, 2.0)
    assert lifted.d_alpha_urad == bare.d_alpha_urad and np.isnan(bare.parallax_m_per_k)


def _modules():
    return [p for p in (ROOT / "monitor").rglob("*.py")] + list((ROOT / "alerts").rglob("*.py"))


def test_a_for_record_is_built_in_one_place():
    """``ForOffset(...)`` is called by the builder (offsets.for_offset) alone; the store, the time series and
    the JSON read records back through ``ForOffset.from_dict``."""
    calls = {
        p.relative_to(ROOT).as_posix()
        for p in _modules()
        for node in ast.walk(ast.parse(p.read_text()))
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "ForOffset"
    }
    assert calls == {"monitor/estimation/offsets.py"}


# the fields that only the science fills and only the declaration publishes (no output or rule reads them
# by name; the calibration rule reads sigma_bias_k): the intercalibration's gain and curvature sigmas, the
# response's and the rows' sigmas, and the lift
FILLED_ONLY = [
    m
    for m in MEASURED_FIELDS
    if m.startswith(("sigma_gain", "sigma_curvature", "sigma_response", "sigma_fov_rows", "parallax_"))
]


@pytest.mark.parametrize("name", FILLED_ONLY)
def test_a_filled_field_is_named_where_declared_computed_and_put_in(name):
    """Such a field is named, as a word, in at most 3 modules: declared, computed, put in the record."""
    named = [p.name for p in _modules() if re.search(rf"\b{name}\b", p.read_text())]
    assert len(named) <= 3, named
