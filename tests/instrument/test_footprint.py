"""The CrIS spatial response model: the named shapes lie within the specification's table, their widths are
the closed forms, and annulus weights give back the widths of the profile they sample."""

import math

import numpy as np
import pytest

from monitor.instrument import footprint
from monitor.instrument.footprint import RadialResponse


@pytest.mark.parametrize("name", ["super-gaussian", "trapezoid", "blurred"])
def test_the_smooth_shapes_are_within_the_specification(name):
    shape = footprint.shape(name)
    assert shape.within_spec() == []
    assert shape.reach_rad > footprint.TOP_HAT.reach_rad  # the response reaches past the 0.963 deg cone
    assert shape(0.0) == 1.0 and shape(shape.reach_rad * 1.01) == 0.0


def test_the_top_hat_cone_is_not():
    assert footprint.TOP_HAT.within_spec()  # 100 % out to 0.963 deg: wider than 0.942 deg at half peak
    assert footprint.TOP_HAT.full_width_rad(0.5) == pytest.approx(math.radians(0.963), rel=1e-3)


def test_widths_are_the_closed_form_of_the_super_gaussian():
    order, r50 = 10.0, footprint.HALF_WIDTH_50_RAD
    shape = footprint.super_gaussian(order, r50)
    for level in (0.7, 0.5, 0.1, 0.03):
        exact = 2 * r50 * (math.log(1 / level) / math.log(2)) ** (1 / order)
        assert shape.full_width_rad(level) == pytest.approx(exact, rel=2e-3)


def test_a_bad_profile_is_refused():
    with pytest.raises(ValueError, match="start at 0"):
        RadialResponse((0.001, 0.01), (1.0, 0.0))
    with pytest.raises(ValueError, match="1 at the centre"):
        RadialResponse((0.0, 0.01), (0.5, 0.0))
    with pytest.raises(ValueError, match="as many"):
        RadialResponse((0.0, 0.01, 0.02), (1.0, 0.0))
    with pytest.raises(ValueError, match="is not one of"):
        footprint.shape("gaussian")


def _edge_scene(seed: int, step_rad: float, n: int) -> np.ndarray:
    """A field of n x n pixels (*step_rad* apart) of overlapping discs of random size and temperature:
    a scene of sharp edges, as clouds make."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:n, :n] * step_rad
    scene = np.full((n, n), 290.0)
    for _ in range(60):
        cx, cy = rng.uniform(0, n * step_rad, 2)
        radius = rng.uniform(0.001, 0.008)
        scene[(x - cx) ** 2 + (y - cy) ** 2 < radius**2] = rng.uniform(210.0, 295.0)
    return scene


def _weighted_means(scene: np.ndarray, step_rad: float, kernel) -> np.ndarray:
    """The scene averaged about every pixel with the weights *kernel*(x_rad, y_rad) (circular)."""
    n = scene.shape[0]
    off = (np.arange(n) - n // 2) * step_rad
    k = kernel(*np.meshgrid(off, off, indexing="ij"))
    k = np.fft.ifftshift(k / k.sum())
    return np.real(np.fft.ifft2(np.fft.fft2(scene) * np.fft.fft2(k)))


@pytest.mark.parametrize(
    "name", ["trapezoid:0.95", "blurred:1.05", "super-gaussian:0.95", "trapezoid:1.02x0.98@30"]
)
def test_the_weights_a_fit_finds_on_edges_give_back_the_response_width(name):
    """Not the model the reader assumes: a scene of discs, the response-weighted mean and the annulus means
    about 3000 points, the weights that reproduce the one from the others best (the estimator's fit).
    Their widths are the truth's within 1.5 %; the weights are not the response's shares per annulus."""
    from monitor.collocation.collocate import ANNULI

    response = footprint.shape(name)
    step, n = 60e-6, 600
    scene = _edge_scene(7, step, n)
    cris = _weighted_means(scene, step, response.at)
    r_in = np.concatenate([[0.0], ANNULI[:-1]])
    annuli = np.stack(
        [
            _weighted_means(
                scene, step, lambda x, y, a=a, b=b: ((np.hypot(x, y) >= a) & (np.hypot(x, y) < b)) * 1.0
            )
            for a, b in zip(r_in, ANNULI, strict=True)
        ],
        axis=-1,
    )
    rng = np.random.default_rng(1)
    edge = int(ANNULI[-1] / step) + 2
    i, j = rng.integers(edge, n - edge, (2, 3000))
    z = annuli[i, j] - cris[i, j, None]
    zc = z - z.mean(axis=0)
    weights = footprint.monotone_weights(zc.T @ zc, ANNULI)
    width = footprint.widths_of_weights(ANNULI, weights)[0.5]
    assert width == pytest.approx(response.full_width_rad(0.5), rel=0.015)


def test_weights_that_are_no_response_have_no_width():
    from monitor.collocation.collocate import ANNULI

    assert all(np.isnan(v) for v in footprint.widths_of_weights(ANNULI, -np.ones(4) / 4).values())
    assert all(np.isnan(v) for v in footprint.widths_of_weights(ANNULI, np.full(4, np.nan)).values())


def test_a_stretched_shape_is_wider_at_every_level():
    base, wide = footprint.shape("trapezoid"), footprint.shape("trapezoid:1.05")
    for level in (0.7, 0.5, 0.1):
        assert wide.full_width_rad(level) == pytest.approx(1.05 * base.full_width_rad(level), rel=1e-9)
    assert any("50 %" in v for v in wide.within_spec())


def test_an_elliptical_shape_reads_between_its_axes_and_turns_with_the_field():
    ell = footprint.shape("super-gaussian:1.03x0.97@30")
    a, b = ell.axis_widths_rad(0.5)
    assert b < ell.full_width_rad(0.5) < a
    assert ell.full_width_rad(0.5) == pytest.approx((a + b) / 2, rel=2e-3)
    assert [v for v in ell.within_spec() if "axis a" in v] and [v for v in ell.within_spec() if "axis b" in v]
    r = 0.95 * b / 2  # within both axes' half width at half peak: above half in every direction
    assert ell.at(np.array([r]), np.array([0.0]))[0] > 0.5
    # along axis a, just within its half width; turned a quarter, the same direction is along the narrower b
    x, y = 0.99 * a / 2 * math.cos(math.radians(30)), 0.99 * a / 2 * math.sin(math.radians(30))
    assert (
        ell.at(np.array([x]), np.array([y]))[0] > 0.5 > ell.at(np.array([x]), np.array([y]), math.pi / 2)[0]
    )


def test_a_bad_stretch_is_refused():
    for spec in ("trapezoid:wide", "trapezoid:-1", "trapezoid:1x0@3", "oval:1.0"):
        with pytest.raises(ValueError, match="footprint"):
            footprint.shape(spec)


def test_a_top_hat_in_annuli_holds_each_annulus_share_of_its_solid_angle():
    radii = (0.004, 0.006, 0.008)
    w = footprint.top_hat_weights(radii, 0.005)
    assert w == pytest.approx([16 / 25, 9 / 25, 0.0])
    assert footprint.top_hat_weights(radii, 0.008) == pytest.approx([16 / 64, 20 / 64, 28 / 64])
