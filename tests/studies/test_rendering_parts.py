"""The parts of a rendering the study gives the simulator's views: each part names the rays it takes, a
part the study does not know fails before any tracing."""

import numpy as np
import pytest

from monitor.collocation.render import Met
from studies.rendering_parts import selected


def test_each_part_takes_the_rays_it_names():
    met = np.full((5, 64, 12), Met.OWN_TOP, np.uint8)
    met[:, 3, 4] = Met.WALL
    met[2, 40, 7] = Met.OTHER_SCAN_TOP
    met[:, :, 0] = Met.NOTHING
    assert selected("rendered", met).sum() == 0 and selected("ideal", met).all()
    assert selected("view:2", met)[2].all() and selected("view:2", met).sum() == 64 * 12
    assert selected("sixths:0-0", met)[:, :, :2].all() and not selected("sixths:0-0", met)[:, :, 2:].any()
    detectors = selected("detectors:0-3", met)
    assert detectors[:, [0, 3, 32, 35]].all() and not detectors[:, [4, 31, 36]].any()
    walls = selected("met:wall", met)
    assert walls.sum() == 5 and walls[:, 3, 4].all()
    assert selected("met:wall+other_scan_top", met).sum() == 6
    others = selected("not-met:wall", met)
    assert not others[:, 3, 4].any() and not others[:, :, 0].any() and others.sum() == 5 * 64 * 11 - 5


@pytest.mark.parametrize("part", ["walls", "met:roof", "view"])
def test_a_part_it_does_not_know_is_an_error(part):
    with pytest.raises(ValueError, match="rendering_parts"):
        selected(part, np.zeros((5, 32, 6), np.uint8))
