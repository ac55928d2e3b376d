"""EP-mode simulated GEO granules shared by the mapping tests."""

import pytest

from monitor.simulate.case import SimulationSpec, simulate_case


@pytest.fixture(scope="session")
def ep_geo_case(tmp_path_factory, error_ep, nominal_ep):
    """Two GEO-only granules made with the nominal EP (truth: the paper-like error EP)."""
    out = tmp_path_factory.mktemp("ep_geo")
    spec = SimulationSpec(
        satellite="j01",
        granules=2,
        seed=4,
        profile="ep",
        cris_sdr=False,
        true_ep=error_ep,
        ground_ep=nominal_ep,
    )
    truth = simulate_case(out, spec=spec, viirs=False)
    return out, truth
