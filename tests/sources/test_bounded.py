"""The stall window of a transfer (no server: a clock the test moves)."""

from monitor.sources.bounded import StallWatch


class Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_a_steady_transfer_never_stalls_and_a_drip_does_after_one_window():
    clock = Clock()
    steady = StallWatch(min_rate_b_s=1000, window_s=30, clock=clock)
    drip = StallWatch(min_rate_b_s=1000, window_s=30, clock=clock)
    for _ in range(120):  # two minutes: 2000 B/s and 1 B/s
        clock.t += 1
        steady.add(2000)
        drip.add(1)
        assert not steady.stalled()
        assert drip.stalled() == (clock.t - 100 >= 30)


def test_a_fast_start_does_not_pay_for_a_later_stall():
    """A total budget let a fast start carry a dead transfer; the window sees only its last 30 s."""
    clock = Clock()
    w = StallWatch(min_rate_b_s=1000, window_s=30, clock=clock)
    clock.t += 1
    w.add(10_000_000)
    for _ in range(29):
        clock.t += 1
        w.add(1)
        assert not w.stalled()
    clock.t += 2
    w.add(1)
    assert w.stalled()
