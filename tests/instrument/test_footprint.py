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
    with pytest.raises(ValueError, match="not one of"):
        footprint.shape("gaussian")


def test_annulus_weights_give_back_the_widths_of_the_profile_they_sample():
    """Weights proportional to a profile's value at each annulus' mid radius times its area: the widths
    found are the profile's, to the annuli's resolution."""
    radii = np.radians([0.36, 0.42, 0.4815, 0.54, 0.60, 0.66])
    inner = np.concatenate([[0.0], radii[:-1]])
    shape = footprint.trapezoid()
    mid = (inner + radii) / 2
    mid[0] = 0.0
    weights = shape(mid) * (radii**2 - inner**2)
    widths = footprint.widths_of_weights(radii, weights / weights.sum())
    assert widths[0.5] == pytest.approx(shape.full_width_rad(0.5), abs=math.radians(0.02))
    assert widths[0.1] == pytest.approx(shape.full_width_rad(0.1), abs=math.radians(0.04))
    assert all(np.isnan(v) for v in footprint.widths_of_weights(radii, -weights).values())
