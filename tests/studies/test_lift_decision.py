"""The lift decision on a flat-cloud day whose texture and footprint differ from the days the rule was
chosen on: it declines the lift, so the day's offsets are those of ``parallax=False``.
Slow (~2 min: a sharp-edged day samples each CrIS cone at 4096 points); the held-back grid is
studies/clouds-with-height.md, sections 3-4."""

import numpy as np
import pytest

from monitor.instrument import footprint
from monitor.simulate.case import simulate_case
from studies.lift_decision import decision


@pytest.mark.slow
def test_a_flat_day_of_sharp_edges_seen_through_a_smooth_footprint_declines_the_lift(tmp_path):
    simulate_case(
        tmp_path,
        granules=3,
        profile="zero",
        seed=73,
        cloud_edges="sharp",
        cris_response=footprint.shape("super-gaussian"),
    )
    row = decision(tmp_path, workers=2, offsets=True)
    assert row["law_m_per_k"] is None and row["kept_m_per_k"] == 0.0, row
    assert row["default"]["lift_m_per_k"] == 0.0 and np.isnan(row["no_parallax"]["lift_m_per_k"])
    same = ("rms_urad", "worst_urad", "rows_median_error_urad", "beta_error_urad")
    assert all(row["default"][k] == row["no_parallax"][k] for k in same), row


@pytest.mark.parametrize("flag", ["--at-lift", "--at-law"])
def test_a_second_pass_asks_for_the_offsets(flag, monkeypatch, tmp_path, capsys):
    from studies import lift_decision

    monkeypatch.setattr("sys.argv", ["lift_decision", str(tmp_path), flag])
    with pytest.raises(SystemExit) as exit_:
        lift_decision.main()
    assert exit_.value.code == 2 and f"{flag} compares offsets" in capsys.readouterr().err
