"""Shared material of the fault-injection suite: copies of the run's small recording and its dataset, and an
evaluation, to damage."""

import shutil

import pytest

from lerobot_tavis.cli import main


@pytest.fixture
def raw_copy(conditional_pick_raw, tmp_path):
    """A copy of the run's two conditional_pick demonstrations (tests/conftest.py) to damage."""
    return shutil.copytree(conditional_pick_raw, tmp_path / "raw")


@pytest.fixture
def dataset_copy(conditional_pick_dataset, tmp_path):
    """A copy of their dataset (20 Hz, the head camera only, 48x64 AV1 video) to damage."""
    return shutil.copytree(conditional_pick_dataset, tmp_path / "dataset")


@pytest.fixture(scope="session")
def eval_root(tmp_path_factory):
    """`tavis eval --expert` of one conditional_pick episode with its `tavis report`, as the folder `step_100/` of
    a checkpoint curve's root (returned)."""
    root = tmp_path_factory.mktemp("faults_eval")
    main(["eval", "--expert", "--tasks", "conditional_pick", "--episodes", "1", "--splits", "id",
          "--out", str(root / "step_100")])
    main(["report", str(root / "step_100")])
    return root


def refused_line(argv: list[str]) -> str:
    """Runs `tavis` in this process and returns the one line it exits with (SystemExit with a text: exit status 1)."""
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    message = exit_info.value.code
    assert isinstance(message, str) and "\n" not in message
    return message


@pytest.fixture
def refused():
    return refused_line
