"""CrIS minus VIIRS per band and FOR over the uniform FOVs, against simulated days whose calibration
difference is known: the same scenes simulated with and without a per-band difference."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from monitor.core.bands import BANDS
from monitor.core.result import AssessmentResult, measures
from monitor.core.vocabulary import BinnedBy
from monitor.matchup import map_granules
from monitor.matchup.radiometry import Uniformity, ascending, day_radiometry, with_radiometry
from monitor.simulate.case import simulate_case
from tests.invoke import run_crisgeo
from tests.matchup.test_run import _truth_result

ALL = tuple(BANDS)
# both signs, 0.05-0.3 K (VIIRS's BT raised by it: CrIS minus VIIRS reads its negative)
INJECTED_K = {"I5": -0.3, "M13": 0.05, "M15": 0.12, "M16": -0.08}
UNIFORM = Uniformity(0.5, 0.97)


CRIS_BIAS_K = 0.2  # CrIS's BT raised in every channel


@pytest.fixture(scope="module")
def twin(tmp_path_factory):
    """A three-granule day simulated three times: as it is, with a calibration difference in every VIIRS
    band, and with CrIS's BT raised in every channel (a random profile and seed, not the shared cases')."""
    out = {}
    for name, bias, cris in (("plain", {}, 0.0), ("biased", INJECTED_K, 0.0), ("cris", {}, CRIS_BIAS_K)):
        d = tmp_path_factory.mktemp(name)
        simulate_case(
            d,
            granules=3,
            seed=21,
            profile="random",
            viirs_bands=ALL,
            viirs_band_bias_k=bias,
            cris_bias_k=cris,
        )
        truth = _truth_result(d)
        matchup, _ = map_granules([d], ALL, offsets=truth)
        out[name] = (truth, matchup)
    return out


def test_each_band_reads_its_injected_difference_with_an_honest_sigma(twin):
    plain = day_radiometry(twin["plain"][1], UNIFORM, ALL)
    biased = day_radiometry(twin["biased"][1], UNIFORM, ALL)
    inside = []
    for p, b in zip(plain.bands, biased.bands, strict=True):
        read = b.mean_k - p.mean_k  # against the same day without it
        assert np.isfinite(read).sum() >= 25, b.band
        assert abs(np.nanmedian(read) + INJECTED_K[b.band]) < 0.03, (b.band, np.nanmedian(read))
        assert np.nanmedian(b.sigma_k) < 0.05, b.band
        # against the truth: the injected difference plus the simulator's own (spectral response cut)
        level = np.nanmedian(p.mean_k)
        ok = np.isfinite(b.mean_k) & np.isfinite(b.sigma_k)
        inside += list(np.abs(b.mean_k[ok] - (level - INJECTED_K[b.band])) <= 2 * b.sigma_k[ok])
    assert np.mean(inside) >= 0.9, np.mean(inside)


def test_a_cris_bias_is_read_the_same_in_every_band(twin):
    plain = day_radiometry(twin["plain"][1], UNIFORM, ALL)
    raised = day_radiometry(twin["cris"][1], UNIFORM, ALL)
    read = {
        b.band: float(np.nanmedian(b.mean_k - p.mean_k))
        for p, b in zip(plain.bands, raised.bands, strict=True)
    }
    assert all(abs(v - CRIS_BIAS_K) < 0.03 for v in read.values()), read


def test_the_bands_leave_the_offsets_as_they_were(twin):
    truth, matchup = twin["biased"]
    result = with_radiometry(truth, day_radiometry(matchup, UNIFORM, ALL))
    banded = {m.name for m in measures() if m.band is not None}
    for before, after in zip(truth.fors, result.fors, strict=True):
        a, b = before.to_dict(), after.to_dict()
        assert {k: v for k, v in a.items() if k not in banded} == {
            k: v for k, v in b.items() if k not in banded
        }


def test_m13_counts_only_warm_scenes_and_the_bins_cover_fov_scene_and_node(twin):
    matchup = twin["biased"][1]
    r = day_radiometry(matchup, UNIFORM, ("M13", "M15"))
    assert [b.band for b in r.bands] == ["M13", "M15"]
    scene = {b.key for b in r.bins if b.band == "M13" and b.by == BinnedBy.SCENE}
    assert scene and min(float(k) for k in scene) >= 260.0
    fov = [b for b in r.bins if b.band == "M15" and b.by == BinnedBy.FOV]
    assert [b.key for b in fov] == [str(i) for i in range(1, 10)] and all(b.n > 0 for b in fov)
    node = {b.key for b in r.bins if b.by == BinnedBy.NODE}
    # the simulated pass is ascending: the latitude rises from scan to scan
    assert node == {"ascending"} and ascending(matchup).all()
    # the bins' FOVs are the FORs' FOVs
    m15 = r.bands[1]
    assert sum(b.n for b in fov) == int(m15.n.sum())
    assert [m.band for m in r.maps] == ["M13", "M15"] and r.maps[1].difference_k.shape[1:] == (30, 9)


def test_a_stricter_uniformity_test_counts_fewer_fovs(twin):
    matchup = twin["plain"][1]
    loose = day_radiometry(matchup, Uniformity(1.0, 0.97), ("I5",)).bands[0]
    strict = day_radiometry(matchup, Uniformity(0.2, 0.97), ("I5",)).bands[0]
    assert strict.n.sum() < loose.n.sum()


def test_the_result_carries_each_band_and_reads_back_from_its_json(twin):
    truth, matchup = twin["biased"]
    result = with_radiometry(truth, day_radiometry(matchup, UNIFORM, ("I5", "M15")))
    f = result.fors[14]
    assert np.isfinite(f.cris_minus_viirs_k_M15) and np.isfinite(f.sigma_cris_minus_viirs_k_M15)
    assert np.isnan(f.cris_minus_viirs_k_M16)  # not compared
    back = AssessmentResult.from_json(json.dumps(result.to_dict()))
    assert back.fors[14].cris_minus_viirs_k_M15 == pytest.approx(f.cris_minus_viirs_k_M15)
    assert [b.to_dict() for b in back.radiometry] == [b.to_dict() for b in result.radiometry]
    assert back.difference_maps[0].band == "I5"
    assert np.array_equal(back.difference_maps[0].uniform, result.difference_maps[0].uniform)


def test_assess_with_the_production_configuration_compares_every_band(cases, tmp_path):
    """``crisgeo assess --config configs/monitor.yaml`` reads only its assessment section (the service's
    folders need not exist here) and writes each band's difference per FOR."""
    case = cases.get(bands=ALL)[0]
    out = tmp_path / "r.json"
    config = Path(__file__).parents[2] / "configs" / "monitor.yaml"
    done = run_crisgeo("assess", case, "--config", config, "--out", out)
    assert done.returncode == 0, done.stderr
    fors = json.loads(out.read_text())["fors"]
    for band in ALL:
        values = [
            f[f"cris_minus_viirs_k_{band}"] for f in fors if f[f"cris_minus_viirs_k_{band}"] is not None
        ]
        # a two-granule day: most FORs have enough uniform FOVs (M13 counts warm scenes only)
        assert len(values) >= 15 and abs(np.median(values)) < 0.1, band
    # and the geolocation read in M15 beside I5's: the same turn within the two bands' sigmas
    read = [f for f in fors if f["d_alpha_urad_M15"] is not None and f["sigma_alpha_urad"] is not None]
    assert len(read) >= 25
    apart = [
        abs(f[f"d_{a}_urad_M15"] - f[f"d_{a}_urad"])
        / np.hypot(f[f"sigma_{a}_urad_M15"], f[f"sigma_{a}_urad"])
        for f in read
        for a in ("alpha", "beta")
    ]
    assert np.median(apart) < 1.5
