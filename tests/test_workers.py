"""Local worker pools: the calling process for one worker, spawned processes otherwise, at a chosen niceness."""

import os
import time

import pytest

from lerobot_tavis.errors import FieldError
from lerobot_tavis.workers import InlineExecutor, cpu_share, executor


def test_local_workers_run_at_the_given_niceness_above_this_process():
    own = os.nice(0)
    with executor(2, niceness=5) as pool:
        seen = {pool.submit(os.nice, 0).result() for _ in range(4)}
    assert seen == {min(own + 5, 19)}
    assert os.nice(0) == own


def test_one_worker_runs_in_this_process_and_keeps_its_niceness():
    own = os.nice(0)
    pool = executor(1, niceness=5)
    assert isinstance(pool, InlineExecutor)
    assert pool.submit(os.getpid).result() == os.getpid() and os.nice(0) == own


@pytest.mark.parametrize("niceness", [-1, 20])
def test_a_niceness_outside_0_to_19_is_refused(niceness):
    with pytest.raises(FieldError, match="niceness must be an integer from 0 to 19"):
        executor(2, niceness=niceness)


@pytest.mark.parametrize(("workers", "cpus"), [(2, [0, 1]), (3, list(range(8))), (4, [2, 5, 7]), (1, [0, 3])])
def test_worker_cpu_shares_differ_and_cover_the_callers_cpus(workers, cpus):
    shares = [cpu_share(index, workers, cpus) for index in range(workers)]
    assert all(share and share <= set(cpus) for share in shares)
    if workers <= len(cpus):
        assert set().union(*shares) == set(cpus) and sum(map(len, shares)) == len(cpus)
    else:
        assert all(len(share) == 1 for share in shares)


def _pid_and_cpus(_) -> tuple[int, frozenset[int]]:
    time.sleep(0.3)  # long enough that every worker takes a job
    return os.getpid(), frozenset(os.sched_getaffinity(0))


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="needs two CPUs to share")
def test_each_local_worker_runs_on_its_own_share_of_the_cpus():
    with executor(2, share_cpus=True) as pool:
        jobs = [pool.submit(_pid_and_cpus, job) for job in range(6)]
        seen = dict(job.result() for job in jobs)
    shares = list(seen.values())
    assert len(shares) == 2 and not shares[0] & shares[1]
    assert shares[0] | shares[1] == os.sched_getaffinity(0)


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="needs two CPUs to share")
def test_without_share_cpus_local_workers_see_every_cpu():
    with executor(2) as pool:
        jobs = [pool.submit(_pid_and_cpus, job) for job in range(4)]
        assert {job.result()[1] for job in jobs} == {frozenset(os.sched_getaffinity(0))}
