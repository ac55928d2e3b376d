import numpy as np
import pytest

from monitor.config.assessment import AssessmentConfig
from monitor.core.result import FLAG_EDGE, FLAG_FEW_SAMPLES, FLAG_FLAT, FLAG_UNCERTAIN, AssessmentResult
from monitor.estimation.cost import find_minimum
from tests.conftest import truth_arrays
from tests.invoke import run_crisgeo


def _bowl(x0, y0, m=21, skew=0.3):
    i, j = np.meshgrid(np.arange(m) - m // 2, np.arange(m) - m // 2, indexing="ij")
    return 0.4 + np.sqrt(0.01 + 0.02 * ((i - x0) ** 2 + skew * (i - x0) * (j - y0) + (j - y0) ** 2))


@pytest.mark.parametrize("x0,y0", [(0.0, 0.0), (2.3, -4.6), (-7.5, 3.25)])
def test_sub_step_minimum(x0, y0):
    x, y, flags = find_minimum(_bowl(x0, y0))
    assert abs(x - x0) < 0.2 and abs(y - y0) < 0.2 and flags == []


def test_edge_and_flat_flags():
    _, _, flags = find_minimum(_bowl(12.0, 0.0))
    assert FLAG_EDGE in flags
    _, _, flags = find_minimum(np.full((21, 21), 0.5) + 1e-4 * np.random.default_rng(0).random((21, 21)))
    assert FLAG_FLAT in flags


def _check_recovery(result, truth, rms_max=60.0, abs_max=150.0, min_reliable=20):
    """Reliable FORs meet the acceptance bounds; the others say why (reduced cases are small)."""
    ta, tb = truth_arrays(truth)
    ok = np.array([f.reliable for f in result.fors])
    assert ok.sum() >= min_reliable
    da = np.array([f.d_alpha_urad for f in result.fors])[ok]
    db = np.array([f.d_beta_urad for f in result.fors])[ok]
    for err in (da - ta[ok], db - tb[ok]):
        assert np.sqrt(np.mean(err**2)) <= rms_max, err
        assert np.max(np.abs(err)) <= abs_max, err
    for f in result.fors:
        if not f.reliable:
            assert FLAG_UNCERTAIN in f.flags and max(f.sigma_alpha_urad, f.sigma_beta_urad) > 250


@pytest.mark.parametrize(
    "profile,seed",
    [("paper", 1), ("random", 2)]
    + [pytest.param(*c, marks=pytest.mark.slow) for c in (("zero", 3), ("paper", 4))],
)
def test_recovers_injected_offsets_on_reduced_cases(cases, profile, seed):
    """Two-granule cases (72 samples per FOR); the 14- and 6-granule acceptance runs are in benchmarks/."""
    _, truth, result = cases.get(profile, seed)
    _check_recovery(result, truth)


def test_result_fields_and_km(cases):
    _, truth, result = cases.get("paper", 1)
    assert len(result.fors) == 30 and [f.for_index for f in result.fors] == list(range(1, 31))
    f30 = result.fors[29]
    assert 3.5 < f30.cross_track_km < 5.0  # ~1750 urad at the end of scan: the paper's ~4 km
    assert f30.total_km == pytest.approx(np.hypot(f30.in_track_km, f30.cross_track_km))
    assert f30.d_beta_pct_fov == pytest.approx(100 * f30.d_beta_urad / 16807.5)
    assert all(f.n_samples == 72 for f in result.fors)  # 2 granules x 4 scans x 9 FOVs, all covered
    assert all(f.sigma_alpha_urad > 0 and f.cost_min_k <= f.cost_zero_k for f in result.fors)
    assert result.fors[29].cost_zero_k > 2 * result.fors[29].cost_min_k  # a sharp, informative minimum
    assert result.cost_cube_k.shape == (30, 21, 21)
    back = AssessmentResult.from_json(result.to_json())
    assert [f.to_dict() for f in back.fors] == [f.to_dict() for f in result.fors]  # NaN as None
    assert np.allclose(back.cost_cube_k, result.cost_cube_k, atol=1e-5)


def test_too_few_samples_are_flagged(cases):
    from monitor.assessment.assess import collocate_run
    from monitor.assessment.estimates import cost_and_offsets
    from monitor.sdr.pairing import plan

    out, _, _ = cases.get("paper", 1)
    case = plan([out])
    samples, _ = collocate_run(case.cris[:1], case.viirs, case.viirs_all, "j01", AssessmentConfig())
    samples[0].usable[:, :, 1:] = False  # keep FOV 1 only: 4 samples per FOR
    result = cost_and_offsets(samples, AssessmentConfig(uncertainty=False), satellite="j01")
    assert all(FLAG_FEW_SAMPLES in f.flags and not f.reliable for f in result.fors)


def test_too_few_usable_fovs_is_an_error_naming_the_files(cases, tmp_path):
    """VIIRS scale factors of 1e30 used to give a table of NaN with exit 0: now the granule is refused and
    the assessment, left with nothing, exits 2 naming the files."""
    import shutil

    import h5py

    out, _, _ = cases.get()
    work = tmp_path / "data"
    work.mkdir()
    for f in out.glob("*.h5"):
        if f.name.startswith("SVI05"):
            shutil.copyfile(f, work / f.name)
            with h5py.File(work / f.name, "r+") as h5:
                h5["All_Data/VIIRS-I5-SDR_All/BrightnessTemperatureFactors"][0] = 1e30
        else:
            (work / f.name).symlink_to(f)
    r = run_crisgeo("assess", work)
    last = r.stderr.strip().splitlines()[-1]  # the log lines before it say which granule was skipped and why
    assert r.returncode == 2 and last.startswith("crisgeo assess: too few usable FOVs to assess: 0"), r.stderr
    assert "SVI05_j01" in last and "scale 1e+30" in last


def test_reading_only_the_reachable_viirs_scans_changes_no_bit(cases, monkeypatch):
    """The VIIRS granules are read over the scans the CrIS granules can reach (and their halos); read
    whole, every offset, sigma, cost and intercalibration value is the same to the bit."""
    from monitor.assessment import assess, inputs

    out, _, partial = cases.get("paper", 1)
    whole_read = inputs.read_viirs
    read_scans = []

    def every_scan(v, viirs_all, span_us=None):
        read_scans.append(span_us)
        return whole_read(v, viirs_all, None)

    monkeypatch.setattr(inputs, "read_viirs", every_scan)
    whole = assess.assess_paths([out], AssessmentConfig())  # as the case was assessed
    assert read_scans and all(s is not None for s in read_scans)  # the partial run had spans to read by
    assert [f.to_dict() for f in whole.fors] == [f.to_dict() for f in partial.fors]
    assert np.array_equal(whole.cost_cube_k, partial.cost_cube_k)


def test_a_day_assessed_in_batches_is_the_day_assessed_at_once(cases, case_plan):
    """Batches in any order give the one-batch estimate: the granules are put back in time order before
    the estimate (the jackknife's consecutive granules), and each is collocated the same way alone. The
    day keeps its cones on disk, reads them back exactly, and removes them when closed."""
    from dataclasses import replace

    from monitor.assessment.assess import DayAssessment
    from monitor.assessment.estimates import cost_and_offsets
    from monitor.assessment.spool import OnDisk

    _, _, at_once = cases.get()
    cfg = AssessmentConfig()
    with DayAssessment(case_plan.satellite, cfg) as day:
        for g in reversed(case_plan.cris):  # the later granule first
            day.add(replace(case_plan, cris=[g], viirs={g.key: case_plan.viirs[g.key]}, skipped=[]))
        batched = day.result()
        kept = day.samples + [s.rendered for s in day.samples]
        assert kept and all(
            isinstance(s.bt_viirs_k, OnDisk) and isinstance(s.annuli_rad, OnDisk) for s in kept
        )

        def in_memory(s):
            rendered = None if s.rendered is None else in_memory(s.rendered)
            return replace(s, bt_viirs_k=s.bt_viirs_k[...], annuli_rad=s.annuli_rad[...], rendered=rendered)

        in_time = sorted(day.samples, key=lambda s: s.info.start)
        memory = cost_and_offsets([in_memory(s) for s in in_time], cfg, day.skipped, day.satellite)
        spool = kept[0].bt_viirs_k.path.parent
    assert [g.granule_id for g in batched.granules] == [g.granule_id for g in at_once.granules]
    assert [f.to_dict() for f in batched.fors] == [f.to_dict() for f in at_once.fors]
    assert [f.to_dict() for f in memory.fors] == [f.to_dict() for f in batched.fors]
    assert not spool.exists()  # removed with the day
