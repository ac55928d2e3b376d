"""The compiled interval formulation of the cone test against a brute-force angle test on every pixel."""

import math
from dataclasses import replace

import numpy as np
import pytest

from monitor.assessment.inputs import KERNELS, SwathCache, piece
from monitor.collocation import collocate, swath
from monitor.compiled.threads import parallel_threads
from monitor.config.assessment import AssessmentConfig
from monitor.geometry import wgs84
from monitor.geometry.inverse import granule_geometry
from monitor.geometry.perturb import perturbation_grid
from monitor.instrument.spectral import i5_band
from monitor.sdr import read_file
from tests.invoke import ROOT


@pytest.fixture(scope="module")
def scene(case_plan):
    g = case_plan.cris[0]
    (geo,) = read_file(g.geo, kinds=("cris_geo",))
    fg = granule_geometry(geo)
    band = i5_band("j01")  # every column prepared (no reach given)
    pieces = [piece(v, case_plan.viirs_all, band, SwathCache(), math.inf) for v in case_plan.viirs[g.key]]
    return fg, swath.ViirsSwath(pieces)


def _one_fov(viirs, fg, idx):
    """The first five arguments of cone_sums for the one FOV *idx* (scan, FOR, FOV) of the geometry fg."""
    return (
        viirs,
        fg.sat_ecef_m[idx][None],
        fg.sbf_to_ecef[idx][None],
        fg.alpha_rad[idx][None],
        fg.beta_rad[idx][None],
    )


def _brute(viirs, sat, m, alpha, beta, offsets, half_angle):
    pos = np.concatenate([p.ecef_m.reshape(-1, 3) for p in viirs.pieces]).astype(float)
    rad = np.concatenate([p.radiance.reshape(-1) for p in viirs.pieces])
    area = np.concatenate([p.area_vec_m2.reshape(-1, 3) for p in viirs.pieces]).astype(float)
    ok = np.isfinite(rad)
    vec = pos[ok] - sat
    dist = np.linalg.norm(vec, axis=1)
    d = vec / dist[:, None]
    los0 = m @ np.array([np.tan(alpha), np.tan(beta), 1.0])
    near = d @ (los0 / np.linalg.norm(los0)) > np.cos(0.05)
    d, dist, val, ar = d[near], dist[near], rad[ok][near], area[ok][near]
    w = np.abs(np.sum(ar * d, axis=1)) / dist**2  # the footprint projected across the view, / range^2
    mean = np.empty((len(offsets), len(offsets)))
    cover = np.empty_like(mean)
    for i, da in enumerate(offsets):
        for j, db in enumerate(offsets):
            los = m @ np.array([np.tan(alpha + da), np.tan(beta + db), 1.0])
            inside = d @ (los / np.linalg.norm(los)) >= np.cos(half_angle)
            mean[i, j] = np.sum(w[inside] * val[inside]) / np.sum(w[inside]) if inside.any() else np.nan
            cover[i, j] = np.sum(w[inside]) / (2 * np.pi * (1 - np.cos(half_angle)))
    return mean, cover


def _brute_fov(viirs, fg, idx, offsets):
    """Brute-force top-hat cone sums of the one FOV *idx* (scan, FOR, FOV) of the geometry fg."""
    sat, m = fg.sat_ecef_m[idx], fg.sbf_to_ecef[idx]
    return _brute(viirs, sat, m, fg.alpha_rad[idx], fg.beta_rad[idx], offsets, collocate.TOP_HAT[0])


@pytest.mark.parametrize("scan,for_,fov", [(1, 14, 4), (2, 29, 8), (0, 0, 0)])
def test_interval_method_equals_brute_force(scene, scan, for_, fov):
    fg, viirs = scene
    offsets = perturbation_grid(4, 900e-6)
    idx = (scan, for_, fov)
    cones = collocate.cone_sums(*_one_fov(viirs, fg, idx), offsets)
    mean, cover = cones.mean(), cones.coverage()
    bm, bc = _brute_fov(viirs, fg, idx, offsets)
    np.testing.assert_allclose(mean[0], bm, rtol=1e-9)
    np.testing.assert_allclose(cover[0], bc, rtol=1e-9)
    # solid-angle weights fill the cone: coverage 1 inside the swath, also at nadir (FOR 15), where the
    # VIIRS scans overlap by a fraction of a detector (whole-pixel counting left ~1.2 % too much there)
    assert np.all(np.abs(bc - 1.0) < 0.01)


def test_fov_off_the_swath_has_no_coverage(scene):
    fg, viirs = scene
    idx = (0, 14, 4)
    far = fg.sat_ecef_m[idx] + np.array([3e6, 0.0, 0.0])
    cones = collocate.cone_sums(
        viirs,
        far[None],
        fg.sbf_to_ecef[idx][None],
        fg.alpha_rad[idx][None],
        fg.beta_rad[idx][None],
        perturbation_grid(2, 450e-6),
    )
    assert np.all(np.nan_to_num(cones.coverage()) < AssessmentConfig().min_coverage)


def test_annuli_are_nested_discs_whose_cone_is_the_top_hat(scene):
    """The footprint's discs: the one of the cone's radius sums exactly what the top-hat kernel sums, the
    weights grow outwards, and the annulus means recombine into each disc's mean."""
    fg, viirs = scene
    idx = (1, 10, 4)
    args = (*_one_fov(viirs, fg, idx), perturbation_grid(2, 450e-6))
    rings = collocate.cone_sums(*args, collocate.ANNULI)
    top = collocate.cone_sums(*args)
    cone = collocate.ANNULI.index(collocate.TOP_HAT[0])
    np.testing.assert_array_equal(rings.sums[:, cone], top.sums[:, 0])
    np.testing.assert_array_equal(rings.weights[:, cone], top.weights[:, 0])
    assert np.all(np.diff(rings.weights, axis=1) > 0) and np.all(np.abs(rings.coverage() - 1) < 0.03)
    a = rings.annulus_means().astype(float)
    w = np.diff(rings.weights, axis=1, prepend=0.0)
    outer = (a * w).sum(axis=1) / w.sum(axis=1)
    np.testing.assert_allclose(outer, rings.mean(-1), rtol=1e-6)
    with pytest.raises(ValueError, match="increase"):
        collocate.cone_sums(*args, collocate.ANNULI[::-1])
    assert KERNELS[AssessmentConfig(kernel="footprint").kernel] == collocate.ANNULI


def test_search_blocks_at_a_ragged_swath_edge(scene, case_plan):
    """Pixels are searched in 4 x 4 blocks; a swath whose width is no multiple of 4 still has every
    pixel of a cone that crosses its last, partial block column counted once."""
    fg, viirs = scene
    idx = (1, 29, 4)
    los = fg.sbf_to_ecef[idx] @ np.array([np.tan(fg.alpha_rad[idx]), np.tan(fg.beta_rad[idx]), 1.0])
    los /= np.linalg.norm(los)
    centre = fg.sat_ecef_m[idx] + wgs84.intersect_ellipsoid(fg.sat_ecef_m[idx], los) * los
    piece = int(np.argmin([p.nearest(centre[None])[2][0] for p in viirs.pieces]))
    row0, col0, _ = viirs.pieces[piece].nearest(centre[None])
    ncol = int(col0[0]) + 4 * 5 + 3  # the cone reaches past the cut
    assert ncol % swath.BLOCK_PX
    v = case_plan.viirs[case_plan.cris[0].key][piece]
    (vgeo,) = read_file(v.geo, kinds=("viirs_geo",))
    (vsdr,) = read_file(v.sdr, kinds=("viirs_sdr",))
    piece = swath.swath_piece(
        vgeo.lat_rad[:, :ncol],
        vgeo.lon_rad[:, :ncol],
        vgeo.height_m[:, :ncol],
        vsdr.bt_k[:, :ncol],
        vsdr.good[:, :ncol],
        i5_band("j01"),
    )
    assert piece.block_radius_m.shape[1] == -(-ncol // swath.BLOCK_PX)
    cut = swath.ViirsSwath([piece])
    offsets = perturbation_grid(2, 900e-6)
    cones = collocate.cone_sums(*_one_fov(cut, fg, idx), offsets)
    mean, cover = cones.mean(), cones.coverage()
    bm, bc = _brute_fov(cut, fg, idx, offsets)
    assert 0.05 < bc.min() and bc.max() < 0.95  # the cut runs through the cones
    np.testing.assert_allclose(mean[0], bm, rtol=1e-9)
    np.testing.assert_allclose(cover[0], bc, rtol=1e-9)


def _synthetic(lat0_deg, lon0_deg, seed, rows=64, cols=160, step_m=400.0, jitter=0.3, holes=0.05):
    """A prepared granule of random pixels around (lat0, lon0): a local east/north grid of *step_m*
    jittered by *jitter* of a step (across a pole, longitudes wrap), random terrain and BT, a fraction
    *holes* unusable; and a satellite 833 km above its centre with an SBF frame whose z axis points at it."""
    rng = np.random.default_rng(seed)
    ground = wgs84.geodetic_to_ecef(np.radians(lat0_deg), np.radians(lon0_deg), 0.0)
    up = ground / np.linalg.norm(ground)
    east = np.cross([0.0, 0.0, 1.0], up) if abs(lat0_deg) < 89 else np.array([0.0, 1.0, 0.0])
    east /= np.linalg.norm(east)
    north = np.cross(up, east)
    r, c = np.meshgrid(np.arange(rows) - rows / 2, np.arange(cols) - cols / 2, indexing="ij")
    r = r + jitter * rng.uniform(-1, 1, r.shape)
    c = c + jitter * rng.uniform(-1, 1, c.shape)
    points = ground + step_m * (r[..., None] * north + c[..., None] * east)
    lat, lon, _ = wgs84.ecef_to_geodetic(points)
    height = rng.uniform(0, 1500, r.shape)
    bt = rng.uniform(200, 300, r.shape)
    good = rng.uniform(size=r.shape) > holes
    piece = swath.swath_piece(lat, lon, height, bt, good, i5_band("j01"))
    sat = ground + 833e3 * up
    z = -up
    x = np.cross([0.3, 0.5, 0.8], z)
    x /= np.linalg.norm(x)
    sbf = np.stack([x, np.cross(z, x), z], axis=1)  # columns: SBF axes in ECEF
    return swath.ViirsSwath([piece]), sat, sbf


@pytest.mark.parametrize(
    "lat0,lon0,seed,alpha,beta",
    [
        (10.0, 20.0, 1, 0.0, 0.0),  # random pixels, cones well inside
        (-35.0, 140.0, 2, 0.004, -0.003),
        (90.0, 0.0, 3, 0.001, 0.002),  # on the pole: longitudes wrap around it
        (-89.98, 45.0, 4, 0.0, 0.001),
        (40.0, -100.0, 5, 0.0, 0.02),  # off the edge: the cones hang over the side of the pixel set
    ],
)
def test_kernel_equals_brute_force_on_random_pixels(lat0, lon0, seed, alpha, beta):
    viirs, sat, sbf = _synthetic(lat0, lon0, seed)
    offsets = perturbation_grid(5, 600e-6)
    for radii in (collocate.TOP_HAT, (0.004,), (0.003, 0.006, 0.009)):  # the nested discs each exact
        cones = collocate.cone_sums(
            viirs, sat[None], sbf[None], np.array([alpha]), np.array([beta]), offsets, radii
        )
        for k, half_angle in enumerate(radii):
            bm, bc = _brute(viirs, sat, sbf, alpha, beta, offsets, half_angle)
            # most cones hold pixels (the edge case: some), at least those of the largest disc
            assert k < len(radii) - 1 or np.isfinite(bm).sum() > 0.3 * bm.size
            np.testing.assert_allclose(cones.mean(k)[0], bm, rtol=1e-9)
            np.testing.assert_allclose(cones.coverage(k)[0], bc, rtol=1e-9, atol=1e-12)


def test_pixels_within_every_cone_of_a_disc_count_in_each():
    """A grid fine against the disc: most pixels lie within every perturbed cone and are added to all of
    them at once; the sums are the brute force's."""
    viirs, sat, sbf = _synthetic(10.0, 20.0, 6)
    offsets = perturbation_grid(5, 40e-6)  # the grid reaches 0.3 mrad, the discs 3-8.4 mrad
    for radii in (collocate.TOP_HAT, (0.003, 0.006)):
        cones = collocate.cone_sums(viirs, sat[None], sbf[None], np.zeros(1), np.zeros(1), offsets, radii)
        for k, half_angle in enumerate(radii):
            bm, bc = _brute(viirs, sat, sbf, 0.0, 0.0, offsets, half_angle)
            assert np.isfinite(bm).all()
            np.testing.assert_allclose(cones.mean(k)[0], bm, rtol=1e-9)
            np.testing.assert_allclose(cones.coverage(k)[0], bc, rtol=1e-9, atol=1e-12)


def test_threads_give_identical_sums(scene):
    """Each FOV accumulates its own sums: 1 or 2 threads give the same bits, and cones on two pieces too."""
    fg, viirs = scene
    sl = (slice(None), slice(10, 14))
    args = (
        viirs,
        fg.sat_ecef_m[sl].reshape(-1, 3),
        fg.sbf_to_ecef[sl].reshape(-1, 3, 3),
        fg.alpha_rad[sl].ravel(),
        fg.beta_rad[sl].ravel(),
        perturbation_grid(3, 450e-6),
    )
    with parallel_threads(1):
        one = collocate.cone_sums(*args)
    with parallel_threads(2):
        two = collocate.cone_sums(*args)
    np.testing.assert_array_equal(one.sums, two.sums)
    np.testing.assert_array_equal(one.weights, two.weights)
    assert np.isfinite(one.mean()).all()


@pytest.mark.parametrize("beta", [-0.96, -0.4, 0.0, 0.3, 0.96])
@pytest.mark.parametrize("n", [1, 10, 20])
def test_run_ends_are_exact_up_to_the_widest_grid(beta, n):
    """The kernel's j of a run end (a chord guess and one comparison) is the exact count of tan B_j
    below t (np.searchsorted), for grids up to MAX_GRID_SPREAD_RAD, ties and points off the grid."""
    from monitor.core.constants import MAX_GRID_SPREAD_RAD

    step = MAX_GRID_SPREAD_RAD / n**2
    tan_b = np.tan(beta + perturbation_grid(n, step))
    m = len(tan_b)
    guess0, scale = tan_b[0], (m - 1) / (tan_b[-1] - tan_b[0])
    rng = np.random.default_rng(n)
    t = np.concatenate(
        [
            np.tan(beta + rng.uniform(-2, 2, 3000) * n * step),
            tan_b,
            np.nextafter(tan_b, np.inf),
            [-np.inf, np.inf],
        ]
    )
    first, after = np.empty(len(t), np.int64), np.empty(len(t), np.int64)
    collocate._run_ends(np.append(tan_b, np.inf), t, t, guess0, scale, first, after)
    np.testing.assert_array_equal(first, np.searchsorted(tan_b, t, "left"))
    np.testing.assert_array_equal(after, np.searchsorted(tan_b, t, "right"))
    nan = np.full(1, np.nan)
    collocate._run_ends(np.append(tan_b, np.inf), nan, nan, guess0, scale, first, after)
    assert first[0] >= after[0]  # an interval of NaN: an empty run


def test_a_grid_beyond_the_kernels_reach_is_refused(scene):
    fg, viirs = scene
    idx = (0, 14, 4)
    with pytest.raises(ValueError, match="n\\^2 s exceeds"):
        collocate.cone_sums(
            *_one_fov(viirs, fg, idx),
            perturbation_grid(30, 450e-6),
        )


def test_warm_up_compiles_the_kernels():
    assert collocate.warm_up() >= 0
    assert collocate._accumulate.signatures and swath._weigh.signatures and swath._locate.signatures


def _two_threads():
    """Prepare and collocate in two threads at once, five times each; the results must agree."""
    import threading

    viirs, sat, sbf = _synthetic(20.0, 30.0, 7)
    offsets = perturbation_grid(3, 450e-6)
    out, errors = [], []

    def work():
        try:
            for _ in range(5):
                _synthetic(20.0, 30.0, 7)  # the preparation kernels
                cones = collocate.cone_sums(viirs, sat[None], sbf[None], np.zeros(1), np.zeros(1), offsets)
                out.append(cones.mean())
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and len(out) == 10
    assert all(np.array_equal(o, out[0], equal_nan=True) for o in out)


def test_two_threads_may_assess_at_once():
    """The daemon may run two satellites' jobs in two threads. Under numba's workqueue threading layer
    (the one left where neither OpenMP nor TBB is installed) concurrent parallel regions terminate the
    process, unless every launch takes threads.KERNEL_LOCK: run it there, in a process of its own."""
    import os
    import subprocess
    import sys

    code = (
        "from tests.collocation.test_collocate import _two_threads; "
        "_two_threads(); print('both threads done')"
    )
    env = dict(os.environ, NUMBA_THREADING_LAYER="workqueue")
    root = ROOT
    r = subprocess.run([sys.executable, "-c", code], env=env, cwd=root, capture_output=True, text=True)
    assert r.returncode == 0 and "both threads done" in r.stdout, r.stderr[-2000:]


def test_each_fov_adds_the_views_about_its_own_in_track_angle(scene):
    """A piece rendered for three in-track angles (here: its radiance, halved, doubled): in the same pass
    as the pixels' own radiance, a FOV at an angle between two views adds their linear blend, one beyond
    the ends the nearest."""
    fg, viirs = scene
    idx = (1, 15, 4)
    alpha = fg.alpha_rad[idx]
    offsets = perturbation_grid(2, 1e-4)
    own = collocate.cone_sums(*_one_fov(viirs, fg, idx), offsets).mean()
    for angles, factor in (
        ((alpha - 0.01, alpha + 0.01, alpha + 0.03), 0.75),
        ((alpha + 0.01, alpha + 0.02, alpha + 0.03), 1.0),
    ):
        views = swath.ViirsSwath(
            [
                replace(
                    p,
                    rendered=np.stack([p.radiance, 0.5 * p.radiance, 2 * p.radiance]),
                    view_alpha_rad=np.array(angles),
                )
                for p in viirs.pieces
            ]
        )
        both = collocate.cone_sums(*_one_fov(views, fg, idx), offsets)
        np.testing.assert_array_equal(both.mean(), own)
        assert both.rendered is not None
        np.testing.assert_allclose(both.rendered.mean(), factor * own, rtol=1e-6)
        np.testing.assert_array_equal(both.rendered.weights, both.weights)
    mixed = swath.ViirsSwath([views.pieces[0], *viirs.pieces])
    with pytest.raises(ValueError, match="all rendered or none"):
        collocate.cone_sums(*_one_fov(mixed, fg, idx), offsets)
