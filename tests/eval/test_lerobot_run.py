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
