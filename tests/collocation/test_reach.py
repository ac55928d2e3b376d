"""Which scans and columns of a VIIRS granule a CrIS granule reaches."""

import numpy as np

from monitor.collocation import reach


def test_scans_between_picks_the_scans_observed_in_a_span():
    start = 1_000_000 + 1_786_000 * np.arange(10)  # IET us, one scan every 1.786 s
    assert reach.scans_between(start, start[2] + 5, start[5]) == slice(2, 6)
    assert reach.scans_between(start, start[2], start[5] - 1) == slice(2, 5)
    assert reach.scans_between(start, 0, start[-1] + 10**9) == slice(0, 10)  # beyond both ends: all
    assert reach.scans_between(start, 0, 1) == slice(0, 1)  # before the granule: its first scan at least
    unusable = start.copy()
    unusable[4] = -993  # a fill time: nothing to judge by
    assert reach.scans_between(unusable, start[2], start[5]) == slice(None)
    assert reach.scans_between(start[::-1], start[2], start[5]) == slice(None)
