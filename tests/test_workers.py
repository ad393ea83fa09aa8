"""Local worker pools: the calling process for one worker, spawned processes otherwise, at a chosen niceness."""

import os

import pytest

from lerobot_tavis.errors import FieldError
from lerobot_tavis.workers import InlineExecutor, executor


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
