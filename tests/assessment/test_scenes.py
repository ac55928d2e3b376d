"""Scene selection on a listing: pairing, coverage, candidates spread over the day, scores, the order of
information per byte, decisions."""

import datetime as dt

from monitor.archive import ALL_PRODUCTS
from monitor.archive.local import LocalSource
from monitor.assessment.scenes import batch_decisions, bytes_of, next_batch, rank_scenes

DAY = dt.date(2024, 6, 1)


def _listing(cases):
    data, _, _ = cases.get()
    source = LocalSource(data)
    return source, source.list_day("j01", DAY, ALL_PRODUCTS)


def test_every_candidate_gets_a_decision_and_the_best_per_byte_come_first(cases):
    source, listing = _listing(cases)
    ranked, decisions = rank_scenes(listing, source, "j01", candidates=40, min_score_k=0.0)
    assert decisions == [] and len(ranked) == 2
    assert all(vs.product == "SVI05" and vg.product == "GITCO" for c in ranked for vs, vg in c.viirs)
    # one VIIRS granule covers both: the order is the score's
    assert ranked[0].score_k >= ranked[1].score_k
    kept = batch_decisions(ranked, sizes=[1], why_not="the day stopped at 1 (one batch)")
    assert [d.decision for d in kept] == ["chosen", "rejected"]
    assert kept[0].reason.endswith("rank 1, batch 1") and "one batch" in kept[1].reason


def test_a_shared_viirs_granule_costs_each_candidate_its_share(cases):
    """At equal score, the candidate whose VIIRS granule another shares costs fewer bytes and comes first."""
    source, listing = _listing(cases)
    ranked, _ = rank_scenes(listing, source, "j01", candidates=40, min_score_k=0.0)
    one = ranked[0]
    (vs, vg) = one.viirs[0]
    alone = bytes_of(one, {vg.parsed.granule_key: 1})
    shared = bytes_of(one, {vg.parsed.granule_key: 2})
    assert alone - shared == (vs.size + vg.size) / 2 > 0
    assert alone == one.sdr.size + one.geo.size + vs.size + vg.size


def test_homogeneous_scenes_and_missing_partners_are_rejected_with_reasons(cases):
    source, listing = _listing(cases)
    chosen, decisions = rank_scenes(listing, source, "j01", candidates=40, min_score_k=1e6)
    assert chosen == [] and all("too homogeneous" in d.reason for d in decisions)
    no_geo = [f for f in listing if f.product != "GCRSO"]
    chosen, decisions = rank_scenes(no_geo, source, "j01", candidates=40, min_score_k=0.0)
    assert chosen == [] and {d.reason for d in decisions} == {"SDR or GEO file missing in the listing"}
    no_viirs = [f for f in listing if f.product in ("SCRIF", "GCRSO")]
    chosen, decisions = rank_scenes(no_viirs, source, "j01", candidates=40, min_score_k=0.0)
    assert chosen == [] and {d.reason for d in decisions} == {"no VIIRS I5 + GEO granule covers it"}


def test_candidates_are_spread_over_the_day(cases):
    source, listing = _listing(cases)
    chosen, decisions = rank_scenes(listing, source, "j01", candidates=1, min_score_k=0.0)
    assert len(chosen) == 1
    assert [d.decision for d in decisions].count("not considered") == 1


def test_the_next_batch_aims_at_the_target_and_at_most_doubles_the_day():
    assert next_batch(14, 5.0, 4.0, keep=14) == 14  # 1/sqrt(N) needs 22: 8 more, but at least keep
    assert next_batch(28, 6.0, 4.0, keep=14) == 28  # needs 63: at most the day so far
    assert next_batch(56, 5.0, 4.0, keep=14) == 32  # needs 87.5 -> 88
    assert next_batch(100, 4.2, 4.0, keep=14) == 14
    assert next_batch(14, None, 4.0, keep=14) == 14  # no sigma yet


def test_the_decisions_name_each_granules_batch(cases):
    source, listing = _listing(cases)
    ranked, _ = rank_scenes(listing, source, "j01", candidates=40, min_score_k=0.0)
    kept = batch_decisions(ranked, sizes=[1, 1], why_not="target reached")
    assert [d.reason.split(", ")[-1] for d in kept] == ["batch 1", "batch 2"]
