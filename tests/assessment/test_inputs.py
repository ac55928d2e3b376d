"""The inputs of a granule's assessment: the prepared VIIRS pieces a time-ordered run keeps."""

from monitor.assessment import inputs
from monitor.assessment.inputs import SwathCache, load_swath
from monitor.instrument.spectral import i5_band


def test_a_piece_no_later_granule_needs_is_freed_before_the_next_is_prepared(case_plan, monkeypatch):
    """A run's CrIS granules come in time order: a VIIRS piece the current granule does not need, no later
    one will. It leaves the cache before a new piece is prepared, so the peak holds what the granule needs
    and not the run's past as well."""
    g = case_plan.cris[0]
    needed = case_plan.viirs[g.key]
    band = i5_band(case_plan.satellite)
    cache = SwathCache()
    cache.pieces["an earlier granule"] = object()
    held = []
    prepare = inputs.swath.swath_piece

    def watched(*args, **kwargs):
        held.append(set(cache.pieces))
        return prepare(*args, **kwargs)

    monkeypatch.setattr(inputs.swath, "swath_piece", watched)
    pieces = load_swath(needed, case_plan.viirs_all, band, cache, 1.0)
    assert len(held) == len(needed) and all("an earlier granule" not in keys for keys in held)
    assert list(cache.pieces) == [v.key for v in needed]
    assert pieces.pieces == list(cache.pieces.values())
