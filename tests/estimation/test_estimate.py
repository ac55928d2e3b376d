"""The estimator on synthetic samples whose truth is known exactly: a smooth CrIS response that the top-hat
cone mistakes, recovered with the annuli; its widths; a calibration difference seen through it."""

import math

import numpy as np
import pytest

from monitor.collocation import collocate
from monitor.core.vocabulary import Cost
from monitor.estimation.estimate import ForSamples, estimate
from monitor.instrument import footprint
from monitor.instrument.spectral import i5_band

STEP_RAD = 450e-6
HALF = 4  # a 9 x 9 grid: enough for the refinement's window about a minimum near the centre
TRUE_STEPS = (0.9, -0.6)  # where CrIS really looks, grid steps from zero turn


def _polar(reach_rad, rings=40, angles=36):
    """Points (P, 2) over a disc of *reach_rad* (rad) and their areas (P,)."""
    edges = np.linspace(0.0, reach_rad, rings + 1)
    r = (edges[1:] + edges[:-1]) / 2
    phi = (np.arange(angles) + 0.5) * 2 * np.pi / angles
    rr, pp = np.meshgrid(r, phi, indexing="ij")
    area = np.repeat((edges[1:] ** 2 - edges[:-1] ** 2) / 2 * (2 * np.pi / angles), angles)
    return np.stack([rr * np.cos(pp), rr * np.sin(pp)], -1).reshape(-1, 2), area


def _scenes(rng, n):
    """Per sample a BT field (K) of angles (u, v) rad: a warm background with cold clouds, each a core and a
    wider, shallower tail towards +u (as anvils drift downwind): a scene whose edges are sharper on one side,
    so that a wrong footprint moves the minimum (on mirror-symmetric scenes it would not, on average)."""
    centres = rng.normal(0.0, 6e-3, (n, 4, 2))
    widths = rng.uniform(2e-3, 5e-3, (n, 4))
    depths = rng.uniform(0.0, 30.0, (n, 4))
    base = rng.normal(298.0, 5.0, n)

    def bt(k, uv):
        rel = uv[..., None, :] - centres[k]
        core = np.exp(-np.sum(rel**2, -1) / (2 * widths[k] ** 2))
        tail = np.exp(-((rel[..., 0] - 2 * widths[k]) ** 2 + rel[..., 1] ** 2) / (8 * widths[k] ** 2))
        return np.maximum(base[k] - np.sum(depths[k] * (core + 0.5 * tail), -1), 200.0)

    return bt


def _samples(response, n=160, seed=1, gain=0.0, bias_k=0.0, noise_k=0.03):
    """ForSamples of *n* FOVs (4 granules) seen by CrIS through *response* at TRUE_STEPS, by VIIRS through
    the annuli of collocate.ANNULI at every turn of the grid; CrIS = VIIRS x (1 + gain) + bias (BT)."""
    rng = np.random.default_rng(seed)
    band = i5_band("j01")
    bt = _scenes(rng, n)
    radii = np.asarray(collocate.ANNULI)
    pts, area = _polar(radii[-1])
    r = np.hypot(pts[:, 0], pts[:, 1])
    ring = np.searchsorted(radii, r)
    turns = (np.arange(-HALF, HALF + 1)) * STEP_RAD
    m = len(turns)
    annuli = np.empty((n, len(radii), m, m), np.float32)
    cone = collocate.ANNULI.index(collocate.TOP_HAT[0])
    d = np.empty((n, m, m))
    true = np.array(TRUE_STEPS) * STEP_RAD
    w_true = response(r) * area
    cris_rad = np.array(
        [np.sum(band.radiance_from_bt(bt(k, pts + true)) * w_true) / w_true.sum() for k in range(n)]
    )
    cris_k = band.bt_from_radiance(cris_rad)
    cris_k = cris_k + gain * (cris_k - 280.0) + bias_k + rng.normal(0.0, noise_k, n)
    for i, a in enumerate(turns):
        for j, b in enumerate(turns):
            rad = band.radiance_from_bt(bt(np.arange(n)[:, None], pts[None] + [a, b]))
            sums = np.stack([np.bincount(ring, rad[k] * area, len(radii)) for k in range(n)])
            areas = np.bincount(ring, area, len(radii))
            annuli[:, :, i, j] = sums / areas
            inside = np.cumsum(sums, axis=1)[:, cone] / np.cumsum(areas)[cone]
            d[:, i, j] = band.bt_from_radiance(inside)
    d -= cris_k[:, None, None]
    granule = np.arange(n) % 4
    return ForSamples(d, cris_k, granule, np.arange(n) // 4 % 4, annuli, collocate.ANNULI, band)


@pytest.fixture(scope="module")
def smooth():
    return _samples(footprint.super_gaussian())


def test_the_annuli_recover_what_the_top_hat_cone_mistakes(smooth):
    top = estimate(ForSamples(smooth.d_k, smooth.cris_k, smooth.granule, smooth.scan), Cost.REGRESSION)
    fit = estimate(smooth, Cost.REGRESSION)
    err_top = np.hypot(top.x - TRUE_STEPS[0], top.y - TRUE_STEPS[1])
    err_fit = np.hypot(fit.x - TRUE_STEPS[0], fit.y - TRUE_STEPS[1])
    assert fit.refined and fit.footprint is not None
    assert err_fit < 0.02  # 9 urad
    assert err_top > 3 * err_fit
    # the jackknife sigma covers the error
    assert err_fit < 3 * max(fit.sigma)


def test_the_fitted_response_has_the_widths_of_the_true_one(smooth):
    fit = estimate(smooth, Cost.REGRESSION).footprint
    truth = footprint.super_gaussian()
    assert fit.width_50_rad == pytest.approx(truth.full_width_rad(0.5), abs=math.radians(0.03))
    assert fit.width_10_rad == pytest.approx(truth.full_width_rad(0.1), abs=math.radians(0.06))
    assert np.isfinite(fit.sigma_width_50_rad) and fit.weights.sum() == pytest.approx(1.0)


def test_a_calibration_difference_is_read_through_the_response():
    """A 2 % gain and a 1 K bias on every CrIS BT: the offsets stay, the intercalibration finds them."""
    differ = estimate(_samples(footprint.trapezoid(), gain=0.02, bias_k=1.0, seed=2), Cost.REGRESSION)
    assert abs(differ.x - TRUE_STEPS[0]) < 0.03 and abs(differ.y - TRUE_STEPS[1]) < 0.03
    cal = differ.intercalibration
    assert cal.gain_pct == pytest.approx(2.0, abs=0.1) and cal.bias_k == pytest.approx(1.0, abs=0.05)
