"""A dataset or an env that does not fit the policy is one line in LeRobot's own CLIs, run as a user runs them (their
console scripts, which import the plugin): `lerobot-train --config_path=<preset>` on a dataset at another image size
than an ACT preset's, and `lerobot-eval --policy.path=<ACT checkpoint> --env.image_size=<another size>`. Both stop
before LeRobot trains or renders anything."""

import json
import os
import subprocess
import sys

from lerobot_tavis.policy_configs import preset_path

CAMERAS = ("head", "left_wrist", "right_wrist")


def _lerobot(command: str, *args: str) -> subprocess.CompletedProcess:
    script = os.path.join(os.path.dirname(sys.executable), command)
    return subprocess.run([script, *args], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "HF_HUB_OFFLINE": "1"})


def _error_lines(result: subprocess.CompletedProcess) -> list[str]:
    return [line for line in result.stderr.splitlines() if ": error: " in line or "Traceback" in line]


def test_lerobot_train_refuses_a_dataset_at_another_size_than_an_act_presets(tmp_path):
    (tmp_path / "dataset" / "meta").mkdir(parents=True)  # the refusal reads meta/info.json alone
    features = {f"observation.images.{camera}": {"dtype": "video", "shape": [96, 128, 3]} for camera in CAMERAS}
    (tmp_path / "dataset" / "meta" / "info.json").write_text(json.dumps({"features": features}))
    result = _lerobot("lerobot-train", f"--config_path={preset_path('act_head_wrist_compact')}",
                      f"--dataset.root={tmp_path / 'dataset'}", "--policy.device=cpu",
                      f"--output_dir={tmp_path / 'train'}")
    assert result.returncode == 1
    assert _error_lines(result) == [
        "lerobot-train: error: the dataset's head images are 96x128, the policy's input_features say 120x160 (and "
        "evaluation renders that): convert the dataset with --image-size 120x160, or set the policy's input shapes "
        "and --env.image_size to 96x128"]
    assert not (tmp_path / "train").exists()


def test_lerobot_eval_refuses_another_image_size_than_an_act_checkpoints(tmp_path):
    checkpoint = tmp_path / "pretrained_model"
    checkpoint.mkdir()
    images = {f"observation.images.{camera}": {"type": "VISUAL", "shape": [3, 120, 160]} for camera in CAMERAS}
    (checkpoint / "config.json").write_text(json.dumps({
        "type": "act", "input_features": images, "output_features": {"action": {"type": "ACTION", "shape": [19]}},
        "device": "cpu"}))
    result = _lerobot("lerobot-eval", f"--policy.path={checkpoint}", "--env.type=tavis", "--env.task=wait_then_act",
                      "--env.image_size=[48,64]", "--eval.n_episodes=1", "--eval.batch_size=1",
                      f"--output_dir={tmp_path / 'eval'}")
    assert result.returncode == 1
    assert _error_lines(result) == [
        "lerobot-eval: error: the policy (act, which does not resize its images) was trained on 120x160 images, "
        "--env.image_size asks for 48x64: leave --env.image_size out to use the checkpoint's"]
