"""The merged pixels' study: a quad is merged only where its BT spans at most the tolerance, and a merged
piece keeps its footprint and, over a uniform scene, the cone means."""

import numpy as np
import pytest

from monitor.collocation.collocate import cone_sums
from monitor.collocation.swath import ViirsSwath, swath_piece
from monitor.core.constants import VIIRS_DETECTORS
from monitor.geometry import wgs84
from monitor.instrument.spectral import i5_band
from studies.merged_pixels import Merged


def _piece(bt_k):
    rows, cols = bt_k.shape
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    lat, lon = np.radians(0.0034 * r).astype(np.float32), np.radians(0.0034 * c).astype(np.float32)
    zeros = np.zeros((rows, cols), np.float32)
    return swath_piece(lat, lon, zeros, bt_k.astype(np.float32), bt_k > 0, i5_band("j01"))


def test_uniform_quads_merge_and_keep_the_footprint_and_the_cone_means():
    rows, cols = 4 * VIIRS_DETECTORS, 240
    bt = np.full((rows, cols), 280.0)
    bt[:, 150:] += 0.2  # uniform within 0.5 K either side of the step
    bt[:, 149] = 281.5  # a column no quad about it merges across
    piece = _piece(bt)
    merged = Merged(0.5, i5_band("j01"))
    out = merged(piece)
    kept = np.isfinite(out.radiance)
    assert merged.merged == (rows // 2) * (cols // 2 - 1) and merged.quads == (rows // 2) * (cols // 2)
    assert kept.sum() == merged.merged + 4 * (rows // 2)
    np.testing.assert_allclose(
        np.linalg.norm(out.area_vec_m2[kept].astype(float), axis=-1).sum(),
        np.linalg.norm(piece.area_vec_m2.astype(float), axis=-1).sum(),
        rtol=1e-5,
    )  # the footprints sum to the same area
    ground = wgs84.geodetic_to_ecef(np.radians(0.0034 * rows / 2), np.radians(0.0034 * 60), 0.0)
    sat = ground * (1 + 833e3 / np.linalg.norm(ground))
    z = -ground / np.linalg.norm(ground)
    x = np.cross([0.0, 0.0, 1.0], z)
    sbf = np.stack([x, np.cross(z, x), z], axis=1)
    offsets = np.linspace(-4.5e-3, 4.5e-3, 5)
    at_nadir = (sat[None], sbf[None], np.zeros(1), np.zeros(1), offsets)
    cones = [cone_sums(ViirsSwath([p]), *at_nadir) for p in (piece, out)]
    np.testing.assert_allclose(cones[1].mean(), cones[0].mean(), rtol=1e-6)  # a uniform scene: the same
    # a cone holds whole quads: its coverage moves by at most its edge's quads, never systematically
    ratio = cones[1].coverage() / cones[0].coverage()
    assert np.abs(ratio - 1).max() < 0.02 and abs(np.mean(ratio) - 1) < 0.005


def test_nothing_merges_where_the_scene_varies_more_than_the_tolerance():
    bt = 280.0 + np.random.default_rng(0).normal(0.0, 1.0, (VIIRS_DETECTORS, 64))
    piece = _piece(bt)
    merged = Merged(0.01, i5_band("j01"))
    out = merged(piece)
    assert merged.merged == 0
    np.testing.assert_array_equal(out.radiance, piece.radiance)


@pytest.mark.parametrize("tolerance_k", [0.3, 3.0])
def test_a_quad_with_an_unusable_pixel_is_not_merged(tolerance_k):
    bt = np.full((VIIRS_DETECTORS, 64), 280.0)
    bt[0, 0] = np.nan
    merged = Merged(tolerance_k, i5_band("j01"))
    out = merged(_piece(np.nan_to_num(bt, nan=-1.0)))
    assert merged.merged == merged.quads - 1 and np.isfinite(out.radiance[1, 1])
