"""Shared material of the fault-injection suite: a small real recording to damage."""

import shutil

import pytest

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
