"""Shared material of the fault-injection suite: a small real recording, its dataset and an evaluation to damage."""

import shutil

import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
from lerobot_tavis.dataset_tools.record import RecordConfig, record


@pytest.fixture(scope="session")
def raw_dir(tmp_path_factory):
    """Two conditional_pick demonstrations (GR1T2), recorded once; tests damage copies of it."""
    out = tmp_path_factory.mktemp("faults") / "raw"
    record(RecordConfig(out_dir=out, robot="gr1t2", tasks=("conditional_pick",), episodes_per_task=2), progress=False)
    return out


@pytest.fixture
def raw_copy(raw_dir, tmp_path):
    return shutil.copytree(raw_dir, tmp_path / "raw")


@pytest.fixture(scope="session")
def dataset_dir(raw_dir, tmp_path_factory):
    """The recording converted once: 20 Hz, the head camera only, 48x64 AV1 video."""
    root = tmp_path_factory.mktemp("faults_dataset") / "dataset"
    return convert(ConvertConfig(raw_dir, "local/faults", root, image_size=(48, 64), cameras=("head",)),
                   progress=False)


@pytest.fixture
def dataset_copy(dataset_dir, tmp_path):
    return shutil.copytree(dataset_dir, tmp_path / "dataset")


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
