"""A synthetic history of daily per-FOR results, for the trend report, dashboards and their benchmarks.

Not the science: a fast stand-in for years of daily runs (paper-like profile, slow drift, noise, one
step at a given day), written through the store's own ``save_day`` like real runs.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import replace
from typing import Any

import numpy as np

from monitor.core.constants import (
    CALIBRATION_BIN_K,
    CALIBRATION_CURVATURE_SPAN_K,
    CALIBRATION_REFERENCE_K,
    DEFAULT_HALF_STEPS,
    DEFAULT_STEP_URAD,
    N_FOR,
)
from monitor.core.result import FLAG_FLAT, AssessmentResult, DifferenceBin
from monitor.estimation.intercal import Intercalibration
from monitor.estimation.offsets import Ground, Pair, Widths, for_offset
from monitor.simulate.profiles import paper_profile

KM_PER_URAD = 0.00083  # at nadir; enough for a picture
# CrIS - VIIRS: a small bias, gain and curvature, as the seeds' intercalibration shows
BIAS_K, GAIN_PCT, CURVATURE_K = 0.15, -0.3, 0.1
# CrIS - VIIRS per band over uniform FOVs (K): a level within the UW intercomparison's 100 mK, and each
# band's per-FOR sigma on a day (the noise drawn is the sigma stated)
BAND_LEVEL_K = {"I5": 0.05, "M13": -0.04, "M15": 0.03, "M16": -0.02}
BAND_SIGMA_K = {"I5": 0.02, "M13": 0.04, "M15": 0.015, "M16": 0.015}
# the offsets read in M15: I5's with the paired difference's noise, and M15's own sigma (urad)
M15_MINUS_I5_SIGMA_URAD, M15_SIGMA_URAD = 10.0, 20.0


def day_result(
    satellite: str,
    day: dt.date,
    rng: np.random.Generator,
    step_urad: float = 0.0,
    with_cube: bool = True,
    band_step_k: dict[str, float] | None = None,
) -> AssessmentResult:
    """One day's result: the paper profile scaled down, noise, and *step_urad* added cross-track at FOR
    21-30; CrIS minus VIIRS in every band at its level with its noise, *band_step_k* added; the offsets read
    in M15 about I5's.

    Parameters
    ----------
    satellite : str
        The satellite.
    day : datetime.date
        The day.
    rng : numpy.random.Generator
        The noise's generator.
    step_urad : float, optional
        Added cross-track at FOR 21-30, urad.
    with_cube : bool, optional
        With a cost cube.
    band_step_k : dict, optional
        Band to K added to its CrIS minus VIIRS at every FOR.

    Returns
    -------
    AssessmentResult
        The result.
    """
    steps = band_step_k or {}
    d_alpha, d_beta = paper_profile()
    d_alpha = 0.3 * d_alpha + rng.normal(0, 15, N_FOR)
    d_beta = 0.3 * d_beta + rng.normal(0, 15, N_FOR) + np.where(np.arange(N_FOR) >= 20, step_urad, 0.0)
    scan = np.abs(np.linspace(-48.3, 48.3, N_FOR))
    stretch = 1.0 / np.cos(np.radians(scan)) ** 2
    # M15's own draws, apart from the day's stream (the other fields' noise stays what it was)
    m15 = np.random.default_rng([day.toordinal(), 15]).normal(0, M15_MINUS_I5_SIGMA_URAD, (N_FOR, 2))
    fors = []
    for k in range(N_FOR):
        it, ct = d_alpha[k] * KM_PER_URAD, d_beta[k] * KM_PER_URAD * stretch[k]
        flags = (FLAG_FLAT,) if rng.random() < 0.01 else ()
        # the intercalibration: bias and its sigma, gain and its sigma, curvature and its sigma
        bias, gain = float(BIAS_K + rng.normal(0, 0.02)), float(GAIN_PCT + rng.normal(0, 0.05))
        cal = Intercalibration(bias, 0.01, gain, 0.03, CURVATURE_K, 0.03)
        ground = Ground(it, ct, 0.01, 0.012 * stretch[k])
        fors.append(
            for_offset(
                k + 1,
                500,
                Pair(d_alpha[k], d_beta[k], 12.0, 14.0),
                ground,
                0.8,
                1.2,
                cal,
                Widths(),
                Pair(),
                np.nan,
                np.nan,
                flags,
            )  # fmt: skip
        )
        bands: dict[str, Any] = {}
        for b, level in BAND_LEVEL_K.items():
            bands[f"cris_minus_viirs_k_{b}"] = level + steps.get(b, 0.0) + rng.normal(0, BAND_SIGMA_K[b])
            bands[f"sigma_cris_minus_viirs_k_{b}"] = BAND_SIGMA_K[b]
        fors[-1] = replace(
            fors[-1],
            **bands,
            d_alpha_urad_M15=d_alpha[k] + m15[k, 0],
            d_beta_urad_M15=d_beta[k] + m15[k, 1],
            sigma_alpha_urad_M15=M15_SIGMA_URAD,
            sigma_beta_urad_M15=M15_SIGMA_URAD,
            m15_minus_i5_alpha_urad=m15[k, 0],
            m15_minus_i5_beta_urad=m15[k, 1],
            sigma_m15_minus_i5_alpha_urad=M15_MINUS_I5_SIGMA_URAD,
            sigma_m15_minus_i5_beta_urad=M15_MINUS_I5_SIGMA_URAD,
        )
    cube = None
    if with_cube:
        off = (np.arange(2 * DEFAULT_HALF_STEPS + 1) - DEFAULT_HALF_STEPS) * DEFAULT_STEP_URAD
        cube = 0.8 + 1e-7 * (
            (off[:, None] - d_alpha[:, None, None]) ** 2 + (off[None, :] - d_beta[:, None, None]) ** 2
        )
    start = dt.datetime(day.year, day.month, day.day, 12, tzinfo=dt.timezone.utc).isoformat()
    lows = np.arange(200.0, 310.0, CALIBRATION_BIN_K)
    bins = [
        DifferenceBin(
            float(low),
            int(n),
            float(BIAS_K + GAIN_PCT / 100 * x + CURVATURE_K * (x / CALIBRATION_CURVATURE_SPAN_K) ** 2),
            0.4,
        )
        for low, n, x in zip(
            lows,
            rng.integers(20, 900, lows.size),
            lows + CALIBRATION_BIN_K / 2 - CALIBRATION_REFERENCE_K,
            strict=True,
        )
    ]
    return AssessmentResult(satellite, start, start, fors, cost_cube_k=cube, difference_bins=bins)


def fill_store(
    store: Any,  # a monitor.service.store.sqlite.Store: the simulator stands below the store's floor
    satellites: list[str],
    first: dt.date,
    days: int,
    step_day: int | None = None,
    step_urad: float = 800.0,
    seed: int = 0,
    cubes: str = "last",
) -> list[dt.date]:
    """Write *days* daily results per satellite from *first*; cost cubes on every day or only the last.

    Parameters
    ----------
    store : Store
        The store written.
    satellites : list of str
        The satellites.
    first : datetime.date
        The first day.
    days : int
        Days per satellite.
    step_day : int, optional
        From this day on, the step.
    step_urad : float, optional
        The step, urad.
    seed : int, optional
        The noise's seed.
    cubes : str, optional
        ``all`` or ``last``.

    Returns
    -------
    list of datetime.date
        The days written.
    """
    rng = np.random.default_rng(seed)
    out = [first + dt.timedelta(days=i) for i in range(days)]
    for sat in satellites:
        for i, day in enumerate(out):
            step = step_urad if step_day is not None and i >= step_day else 0.0
            result = day_result(sat, day, rng, step, with_cube=cubes == "all" or i == days - 1)
            run = store.begin_run(sat, day)
            store.save_day(run, sat, day, result)
    return out
