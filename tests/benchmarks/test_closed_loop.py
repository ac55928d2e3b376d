"""The whole loop of section 4: assess -> optimize -> regeolocate -> assess again."""

import numpy as np
import pytest

from benchmarks.closed_loop import run_closed_loop


def _check(rep):
    a2, b2, it, ct = rep.residual()
    assert np.max(np.abs(rep.roll_error_urad)) <= 100 and np.max(np.abs(rep.pitch_error_urad)) <= 100, (
        rep.table()
    )
    assert np.nanmax(np.abs(a2)) <= 150 and np.nanmax(np.abs(b2)) <= 150, rep.table()
    assert np.nanmax(np.abs(it)) <= 0.15 and np.nanmax(np.abs(ct)) <= 0.15, rep.table()
    # the first assessment did see the injected error (up to ~1200 urad cross-track at FOR 30)
    assert rep.first.fors[29].d_beta_urad > 1000


@pytest.mark.parametrize(
    "granules,seed",
    [(2, 2), pytest.param(4, 2, marks=pytest.mark.slow), pytest.param(14, 1, marks=pytest.mark.slow)],
)
def test_closed_loop(tmp_path, error_ep, nominal_ep, granules, seed):
    _check(run_closed_loop(tmp_path, error_ep, nominal_ep, granules=granules, seed=seed))
