"""`--backend ray`: the same jobs on a Ray cluster (a head started on this machine) give the local backend's
results, for the demonstrator protocol and for recording."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from lerobot_tavis.dataset_tools.raw import Manifest
from lerobot_tavis.dataset_tools.record import RecordConfig, record
from lerobot_tavis.eval.protocol import ProtocolConfig, run_protocol
from tests.conftest import free_port

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

RAY = str(Path(sys.executable).with_name("ray"))


@pytest.fixture(scope="module")
def ray_cluster():
    """A one-node Ray cluster (`ray start --head`), reached as a remote cluster is: through RAY_ADDRESS."""
    port = free_port()
    temp_dir = Path(f"/tmp/ray-tavis-{os.getpid()}")  # Ray's socket paths must stay short
    subprocess.run([RAY, "start", "--head", f"--port={port}", "--num-cpus=2", "--num-gpus=0", "--disable-usage-stats",
                    "--include-dashboard=false", f"--temp-dir={temp_dir}"], check=True, capture_output=True)
    previous = os.environ.get("RAY_ADDRESS")
    os.environ["RAY_ADDRESS"] = f"127.0.0.1:{port}"
    try:
        yield
    finally:
        if previous is None:
            os.environ.pop("RAY_ADDRESS")
        else:
            os.environ["RAY_ADDRESS"] = previous
        subprocess.run([RAY, "stop", "--force"], capture_output=True)


def _cell(root: Path, name: str = "tavis_hands__id") -> tuple[str, dict]:
    info = json.loads((root / name / "eval_info.json").read_text())
    return (root / name / "episodes.jsonl").read_text(), info


def test_demonstrator_protocol_on_ray_equals_local(tmp_path, ray_cluster):
    common = dict(expert=True, robot="gr1t2", suites=("tavis_hands",), splits=("id",), n_episodes=2,
                  chunk_episodes=1, episode_length_s=2.0)  # each episode's first seconds: the same or not
    run_protocol(ProtocolConfig(out_dir=tmp_path / "local", workers=1, **common))
    run_protocol(ProtocolConfig(out_dir=tmp_path / "ray", workers=2, backend="ray", **common))
    assert _cell(tmp_path / "ray") == _cell(tmp_path / "local")
    assert not list((tmp_path / "ray").glob(".*"))


def test_recording_on_ray_equals_local(tmp_path, ray_cluster, conditional_pick_raw):
    """Against the run's local recording (tests/conftest.py: the same robot, task, count and seeds)."""
    local = Manifest.load(conditional_pick_raw)
    remote = record(RecordConfig(out_dir=tmp_path / "ray", robot="gr1t2", tasks=("conditional_pick",),
                                 episodes_per_task=2, workers=2, backend="ray"), progress=False)
    entries = [sorted((e.seed, e.success, e.n_steps, e.sha256) for e in m.episodes) for m in (local, remote)]
    assert entries[0] == entries[1] and len(entries[0]) >= 2
    assert Manifest.load(tmp_path / "ray").episodes  # the manifest on disk, written by this process
