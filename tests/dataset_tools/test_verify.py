"""`tavis verify-dataset`: a converted dataset (the run's two conditional_pick demonstrations, tests/conftest.py)
replays as recorded; actions misaligned by one frame do not."""

import json
import shutil

import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools.convert import CONVERSION_LOG
from lerobot_tavis.dataset_tools.verify import TOLERANCE_M, verify_dataset


def test_a_converted_dataset_replays_as_recorded(conditional_pick_dataset, capsys):
    main(["verify-dataset", str(conditional_pick_dataset)])
    out = capsys.readouterr().out
    assert "2 episodes replay as recorded" in out and out.count(": ok") == 2


@pytest.mark.parametrize("shift", [1, -1])
def test_actions_one_frame_off_are_caught(conditional_pick_dataset, shift):
    checks = verify_dataset(conditional_pick_dataset, action_shift=shift)
    assert all(check.max_hand_error_m > 1.5 * TOLERANCE_M and not check.passed for check in checks)


def test_a_failing_dataset_exits_with_the_episodes_named(conditional_pick_dataset, tmp_path, capsys):
    broken = shutil.copytree(conditional_pick_dataset, tmp_path / "broken")
    log_path = broken / CONVERSION_LOG
    log = json.loads(log_path.read_text())
    log["episodes"][1]["seed"] += 1  # episode 1 now claims another scene
    log_path.write_text(json.dumps(log))
    with pytest.raises(SystemExit, match=r"1 of 2 episodes do not replay as recorded .*: \[1\]"):
        main(["verify-dataset", str(broken)])
    assert "episode    0" in capsys.readouterr().out


def test_bad_input_is_a_clear_error(conditional_pick_dataset, tmp_path):
    with pytest.raises(SystemExit, match="no episodes \\[5\\]; it holds 0..1"):
        main(["verify-dataset", str(conditional_pick_dataset), "--episodes", "5"])
    plain = shutil.copytree(conditional_pick_dataset, tmp_path / "plain")
    (plain / CONVERSION_LOG).unlink()
    with pytest.raises(SystemExit, match="only datasets written by `tavis convert` can be replayed"):
        main(["verify-dataset", str(plain)])
