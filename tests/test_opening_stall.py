"""benchmarks/opening_stall.py: with the fixed and wrist cameras and the neck zeroed, a conditional_pick
demonstration opens with inputs that stay the same until the arms move; with the head camera the head's first
saccade changes them much sooner."""

import pytest

from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
from lerobot_tavis.dataset_tools.record import RecordConfig, record


@pytest.fixture(scope="module")
def raw_dir(tmp_path_factory):
    """Two conditional_pick demonstrations (GR1T2)."""
    raw = tmp_path_factory.mktemp("stall") / "raw"
    record(RecordConfig(out_dir=raw, robot="gr1t2", tasks=("conditional_pick",), episodes_per_task=2), progress=False)
    return raw


def _stalls(benchmark_script, raw_dir, cameras, zero_neck):
    root = convert(ConvertConfig(raw_dir, "local/stall", raw_dir.parent / "_".join(cameras), image_size=(48, 64),
                                 cameras=cameras, zero_neck=zero_neck), progress=False)
    return benchmark_script("opening_stall").opening_stalls(root)


def test_fixed_camera_inputs_stay_the_same_until_the_arms_move(benchmark_script, raw_dir):
    stalls, fps = _stalls(benchmark_script, raw_dir, ("fixed", "left_wrist", "right_wrist"), zero_neck=True)
    assert fps == 20 and len(stalls) == 2
    for stall in stalls:
        assert stall.frames >= 18  # the demonstrator looks at the card for 0.9 s or more
        assert stall.arm_action is not None and abs(stall.frames - stall.arm_action) <= 1


def test_the_head_camera_shows_the_opening_look(benchmark_script, raw_dir):
    stalls, _ = _stalls(benchmark_script, raw_dir, ("head",), zero_neck=False)
    for stall in stalls:
        assert stall.frames <= 12 and stall.images["head"] <= 12
        assert stall.arm_action > stall.frames + 5


def test_a_folder_that_is_not_a_dataset_is_a_clear_error(benchmark_script, tmp_path):
    with pytest.raises(SystemExit, match="is not a LeRobotDataset folder"):
        benchmark_script("opening_stall").opening_stalls(tmp_path)
