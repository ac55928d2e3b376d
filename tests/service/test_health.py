"""The daemon's health: jobs over budget and a silent scheduler, on a clock the test turns."""

import threading

from monitor.service.health import Health
from tests.conftest import Clock


def test_a_job_over_its_budget_is_a_problem_until_it_ends():
    clock = Clock()
    h = Health(stall_s=300, clock=clock)
    assert h.problems() == []
    with h.job("run j01 2026-11-21", budget_s=60):
        clock.t += 59
        assert h.problems() == [] and h.running()[0]["job"] == "run j01 2026-11-21"
        clock.t += 2
        h.beat()
        (problem,) = h.problems()
        assert problem.startswith("run j01 2026-11-21: running for 61 s, over its budget of 60 s")
    assert h.problems() == [] and h.running() == []


def test_a_silent_scheduler_is_a_problem_until_it_beats_again():
    clock = Clock()
    h = Health(stall_s=300, clock=clock)
    clock.t += 301
    assert h.problems() == ["scheduler: no heartbeat for 301 s (stalled after 300 s)"]
    h.beat()
    assert h.problems() == []


def test_jobs_from_threads_are_tracked_apart():
    clock = Clock()
    h = Health(stall_s=1e9, clock=clock)
    inside, release = threading.Barrier(3), threading.Event()

    def work(name, budget):
        with h.job(name, budget):
            inside.wait()
            release.wait()

    threads = [threading.Thread(target=work, args=(n, b)) for n, b in (("short", 1), ("long", 100))]
    for t in threads:
        t.start()
    inside.wait()
    clock.t += 10
    assert [p.split(":")[0] for p in h.problems()] == ["short"]
    release.set()
    for t in threads:
        t.join()
    assert h.running() == []
