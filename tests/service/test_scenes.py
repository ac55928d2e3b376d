"""Scene selection on a listing: pairing, coverage, candidates spread over the day, scores, decisions."""

import datetime as dt

from monitor.service.scenes import select_scenes
from monitor.service.sources import ALL_PRODUCTS
from monitor.service.sources.local import LocalSource

DAY = dt.date(2024, 6, 1)


def _listing(cases):
    data, _, _ = cases.get()
    source = LocalSource(data)
    return source, source.list_day("j01", DAY, ALL_PRODUCTS)


def test_every_candidate_gets_a_decision_and_the_best_are_kept(cases):
    source, listing = _listing(cases)
    chosen, decisions = select_scenes(listing, source, "j01", candidates=40, keep=1, min_score_k=0.0)
    assert len(chosen) == 1 and all(
        vs.product == "SVI05" and vg.product == "GITCO" for vs, vg in chosen[0].viirs
    )
    by_decision = {}
    for d in decisions:
        by_decision.setdefault(d.decision, []).append(d)
    assert len(by_decision["chosen"]) == 1 and len(by_decision["rejected"]) == 1
    assert "more inhomogeneous granules were kept" in by_decision["rejected"][0].reason
    assert by_decision["chosen"][0].score_k >= by_decision["rejected"][0].score_k


def test_homogeneous_scenes_and_missing_partners_are_rejected_with_reasons(cases):
    source, listing = _listing(cases)
    chosen, decisions = select_scenes(listing, source, "j01", candidates=40, keep=14, min_score_k=1e6)
    assert chosen == [] and all("too homogeneous" in d.reason for d in decisions)
    no_geo = [f for f in listing if f.product != "GCRSO"]
    chosen, decisions = select_scenes(no_geo, source, "j01", candidates=40, keep=14, min_score_k=0.0)
    assert chosen == [] and {d.reason for d in decisions} == {"SDR or GEO file missing in the listing"}
    no_viirs = [f for f in listing if f.product in ("SCRIF", "GCRSO")]
    chosen, decisions = select_scenes(no_viirs, source, "j01", candidates=40, keep=14, min_score_k=0.0)
    assert chosen == [] and {d.reason for d in decisions} == {"no VIIRS I5 + GEO granule covers it"}


def test_candidates_are_spread_over_the_day(cases):
    source, listing = _listing(cases)
    chosen, decisions = select_scenes(listing, source, "j01", candidates=1, keep=14, min_score_k=0.0)
    assert len(chosen) == 1
    assert [d.decision for d in decisions].count("not considered") == 1
