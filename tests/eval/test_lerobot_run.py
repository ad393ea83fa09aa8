import os
import subprocess
import sys

import numpy as np
import pytest
import torch
from lerobot.envs.utils import preprocess_observation
from lerobot.scripts import lerobot_eval

from lerobot_tavis.eval.lerobot_run import images_converted_on

DEVICES = ["cpu", pytest.param("cuda", marks=pytest.mark.skipif(not torch.cuda.is_available(), reason="no GPU"))]


def vector_observation(rng, n_envs=3):
    images = {name: rng.integers(0, 256, (n_envs, 12, 16, 3), dtype=np.uint8) for name in ("head", "left_wrist")}
    return {"pixels": images, "agent_pos": rng.normal(size=(n_envs, 19)).astype(np.float32)}


@pytest.mark.parametrize("device", DEVICES)
def test_images_converted_on_the_device_equal_lerobots_conversion(device):
    observation = vector_observation(np.random.default_rng(0))
    expected = preprocess_observation(observation)
    with images_converted_on(torch.device(device)):
        converted = lerobot_eval.preprocess_observation(observation)
    assert list(converted) == list(expected)
    for key, value in expected.items():
        assert converted[key].dtype == value.dtype
        assert converted[key].device.type == (device if key.startswith("observation.images.") else "cpu")
        assert torch.equal(converted[key].cpu(), value), key
    assert lerobot_eval.preprocess_observation is preprocess_observation  # restored on leaving


def test_one_env_gets_a_batch_dimension_and_bad_images_are_refused():
    observation = vector_observation(np.random.default_rng(1), n_envs=1)
    one_env = {"pixels": {name: image[0] for name, image in observation["pixels"].items()}}
    with images_converted_on(torch.device("cpu")):
        converted = lerobot_eval.preprocess_observation(one_env)
        assert converted["observation.images.head"].shape == (1, 3, 12, 16)
        with pytest.raises(ValueError, match="uint8, channel last"):
            lerobot_eval.preprocess_observation({"pixels": {"head": np.zeros((1, 3, 12, 16), np.uint8)}})
        with pytest.raises(ValueError, match="uint8, channel last"):
            lerobot_eval.preprocess_observation({"pixels": {"head": np.zeros((1, 12, 16, 3), np.float32)}})
    assert lerobot_eval.preprocess_observation is preprocess_observation


KEEP_AND_EXIT = """
import multiprocessing, sys

def keep_a_batch():  # the job imports what it needs; the parent only starts it
    from lerobot_tavis.eval.env_config import TavisEnvConfig
    from lerobot_tavis.eval import lerobot_run

    batch = TavisEnvConfig(task="conditional_pick", image_size=(24, 32)).create_envs(2, True)["tavis_head"][0]
    batch.reset(seed=0)
    lerobot_run._KEPT["kept"] = batch  # as a policy job leaves it between chunks
    print("workers", *(process.pid for process in batch._started().processes), file=sys.stderr)

if __name__ == "__main__":
    job = multiprocessing.get_context("spawn").Process(target=keep_a_batch)
    job.start()
    job.join()
    sys.exit(job.exitcode)
"""


def test_a_job_that_exits_closes_its_kept_env_workers_cleanly(tmp_path):
    """A policy job's kept env workers are closed before multiprocessing terminates them at the job's exit (a
    close after that wrote a BrokenPipeError traceback per job)."""
    script = tmp_path / "keep_and_exit.py"
    script.write_text(KEEP_AND_EXIT)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "MUJOCO_GL": "egl"})
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr
    workers = [int(pid) for line in done.stderr.splitlines() if line.startswith("workers ") for pid in line.split()[1:]]
    assert len(workers) == 2 and not any(os.path.exists(f"/proc/{pid}") for pid in workers)
