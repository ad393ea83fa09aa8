"""Policy presets: they parse with LeRobot's loader, match a converted dataset and the env, a diffusion preset
trains, evaluates periodically on the tavis env and leaves a checkpoint that lerobot-eval runs, and a compact ACT
without the state input (absolute or hand-frame actions) trains and runs in `tavis eval`."""

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
from lerobot_tavis.policy_configs import build_preset, preset_names, preset_path, presets

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

TINY = (48, 64)
# Small enough for a CPU: the preset's network shrunk, 1-second episodes, two denoising steps.
SMALL_RUN = ["--env.task=conditional_pick", f"--env.image_size=[{TINY[0]},{TINY[1]}]", "--env.episode_length_s=1",
             f"--policy.resize_shape=[{TINY[0]},{TINY[1]}]", "--policy.down_dims=[16,32,64]",
             "--policy.num_inference_steps=2", "--policy.device=cpu"]


@pytest.fixture(scope="module")
def dataset_root(conditional_pick_demonstration, tmp_path_factory):
    """One conditional_pick demonstration converted with all four cameras at 48x64."""
    return convert(ConvertConfig(conditional_pick_demonstration, "local/tiny",
                                 tmp_path_factory.mktemp("presets") / "dataset", image_size=TINY), progress=False)


def _parse(name, *overrides):
    import draccus
    import lerobot.policies  # noqa: F401  (registers the policy types)
    from lerobot.configs.train import TrainPipelineConfig

    import lerobot_env_tavis  # noqa: F401  (registers the env type, as LeRobot's CLIs do)

    return draccus.parse(TrainPipelineConfig, config_path=str(preset_path(name)), args=list(overrides))


def test_the_shipped_files_are_the_generated_presets():
    assert len(preset_names()) == 14
    for name, (policy, mode, compact) in presets().items():
        assert json.loads(preset_path(name).read_text()) == build_preset(policy, mode, compact), name
    with pytest.raises(ValueError, match="unknown preset"), pytest.warns(FutureWarning, match="now called 'head_only'"):
        preset_path("act_headcam")  # the old name of head_only, which has no ACT preset
    with pytest.raises(ValueError, match="compact presets exist for"):
        build_preset("act", "head_only", compact=True)
    with pytest.raises(ValueError, match="compact presets are of act, act_hand_relative, diffusion_hand_relative"):
        build_preset("diffusion", "head_wrist", compact=True)


@pytest.mark.parametrize("name", preset_names())
def test_every_preset_parses_and_matches_the_dataset_and_the_env(name, dataset_root):
    from lerobot.datasets.lerobot_dataset import LeRobotDatasetMetadata
    from lerobot.utils.feature_utils import dataset_to_policy_features

    cfg = _parse(name, "--dataset.repo_id=local/tiny", f"--dataset.root={dataset_root}")
    policy, mode, _ = presets()[name]
    assert cfg.policy.type == policy and cfg.env.type == "tavis" and cfg.env.camera_mode == mode
    batch = {"act": 64, "act_hand_relative": 128, "diffusion_hand_relative": 128}.get(policy, 16)
    assert (cfg.policy.n_action_steps, cfg.batch_size) == ((10 if policy.startswith("act") else 8), batch)
    dataset_features = dataset_to_policy_features(LeRobotDatasetMetadata("local/tiny", root=dataset_root).features)
    env_keys = set(cfg.env.features_map.values())
    for key, feature in cfg.policy.input_features.items():
        assert key in dataset_features and key in env_keys, key
        assert dataset_features[key].shape[0] == feature.shape[0]  # channels / state size
    cameras = {k.rsplit(".", 1)[1] for k in cfg.policy.input_features if k.startswith("observation.images.")}
    assert cameras == ({"head"} if mode.startswith("head") else {"fixed"}) | (
        {"left_wrist", "right_wrist"} if mode.endswith("wrist") else set())
    if policy == "diffusion":
        assert (cfg.policy.n_obs_steps, cfg.policy.horizon, cfg.policy.optimizer_lr) == (2, 16, 1e-4)
        assert tuple(cfg.policy.resize_shape) == (240, 320) == tuple(cfg.env.image_size)
        assert cfg.policy.pretrained_backbone_weights is None and cfg.policy.use_group_norm
        assert cfg.policy.noise_scheduler_type == "DDPM"
    elif policy == "diffusion_hand_relative":
        assert (cfg.policy.n_obs_steps, cfg.policy.horizon, cfg.policy.drop_n_last_frames) == (2, 16, 7)
        assert tuple(cfg.policy.resize_shape) == (120, 160) == tuple(cfg.env.image_size)
        assert cfg.policy.crop_shape is None and tuple(cfg.policy.down_dims) == (256, 512, 1024)
        assert cfg.policy.pretrained_backbone_weights is None and cfg.policy.use_group_norm
        assert (cfg.policy.time_input, cfg.policy.state_input) == (True, "none")
        assert (cfg.steps, cfg.save_freq) == (3200, 800)
    elif policy.startswith("act"):
        assert (cfg.policy.chunk_size, cfg.policy.optimizer_lr, cfg.policy.optimizer_lr_backbone) == (20, 1e-4, 1e-4)
        assert cfg.policy.pretrained_backbone_weights is None and tuple(cfg.env.image_size) == (120, 160)
        assert all(f.shape[1:] == (120, 160) for k, f in cfg.policy.input_features.items() if "images" in k)
        hand_relative = policy == "act_hand_relative"
        assert ("observation.state" in cfg.policy.input_features) is not hand_relative
        assert (cfg.steps, cfg.save_freq) == ((3200, 800) if hand_relative else (6000, 2000))
        assert getattr(cfg.policy, "time_input", False) is hand_relative
    else:
        assert (cfg.policy.chunk_size, cfg.policy.optimizer_lr) == (16, 2.5e-5)
        assert str(cfg.policy.pretrained_path) == "lerobot/pi0_base"


@pytest.mark.parametrize("name", [name for name, (_, _, compact) in presets().items() if compact])
def test_compact_presets_anneal_the_learning_rate_to_zero_at_the_last_step(name):
    import torch
    from lerobot.optim.factory import make_optimizer_and_scheduler

    cfg = _parse(name, "--steps=40")
    optimizer, scheduler = make_optimizer_and_scheduler(cfg, torch.nn.Linear(2, 2))
    rates = []
    for _ in range(cfg.steps + 1):
        rates.append(optimizer.param_groups[0]["lr"])
        optimizer.step()
        scheduler.step()
    assert rates[0] == pytest.approx(1e-4) and rates[20] == pytest.approx(5e-5) and rates[40] == pytest.approx(0.0)
    assert all(later <= earlier for earlier, later in zip(rates, rates[1:]))
    assert (optimizer.defaults["weight_decay"], cfg.optimizer.grad_clip_norm) == (1e-4, 10.0)


def test_zero_neck_conversion_for_the_fixed_camera_presets(conditional_pick_demonstration, tmp_path):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    root = convert(ConvertConfig(conditional_pick_demonstration, "local/zero", tmp_path / "zero", image_size=TINY,
                                 cameras=("fixed",), zero_neck=True), progress=False)
    table = LeRobotDataset("local/zero", root=root, video_backend="pyav").hf_dataset
    state, action = (np.stack(table[key]) for key in ("observation.state", "action"))
    assert np.all(state[:, canonical.HEAD] == 0) and np.all(action[:, canonical.HEAD] == 0)
    assert np.any(action[:, canonical.LEFT.position] != 0)


def test_a_diffusion_preset_trains_evaluates_and_its_checkpoint_runs_in_lerobot_eval(dataset_root, tmp_path,
                                                                                     monkeypatch):
    """lerobot-train with its periodic evaluation in the env, then lerobot-eval of the checkpoint, both through their
    entry points in this process (lerobot-train's own processes, which find the plugin as LeRobot does, are in
    tests/dataset_tools/test_frame_cache.py; lerobot-eval's console script in tests/eval/test_protocol.py)."""
    from lerobot.scripts import lerobot_eval

    _lerobot_train_in_this_process(
        monkeypatch, f"--config_path={preset_path('diffusion_head_only')}", "--dataset.repo_id=local/tiny",
        f"--dataset.root={dataset_root}", *SMALL_RUN, "--steps=2", "--env_eval_freq=2", "--save_freq=2",
        "--batch_size=2", "--num_workers=0", "--eval.n_episodes=1", "--eval.batch_size=1",
        "--eval.use_async_envs=false", f"--output_dir={tmp_path / 'train'}")
    (periodic,) = [json.loads(line) for line in (tmp_path / "train" / "episodes.jsonl").read_text().splitlines()]
    assert periodic["task"] == "conditional_pick" and periodic["camera_mode"] == "head_only"
    checkpoint = tmp_path / "train" / "checkpoints" / "last" / "pretrained_model"
    monkeypatch.setattr("sys.argv", [
        "lerobot-eval", f"--policy.path={checkpoint}", "--policy.device=cpu", "--env.type=tavis",
        "--env.task=conditional_pick", f"--env.image_size=[{TINY[0]},{TINY[1]}]", "--env.episode_length_s=1",
        "--eval.n_episodes=1", "--eval.batch_size=1", "--eval.use_async_envs=false",
        f"--output_dir={tmp_path / 'eval'}"])
    monkeypatch.setenv("HF_HUB_OFFLINE", "1")
    lerobot_eval.eval_main()
    info = json.loads((tmp_path / "eval" / "eval_info.json").read_text())
    assert info["overall"]["n_episodes"] == 1


@pytest.mark.parametrize(("name", "policy_type", "options"), [
    ("act_head_wrist_compact", "act", {}),
    ("act_hand_relative_head_wrist_compact", "act_hand_relative", {"backbone_norm": "group_norm",
                                                                   "prompt_input": True})])
def test_a_compact_act_without_the_state_input_trains_and_tavis_eval_runs_it(dataset_root, tmp_path, name,
                                                                             policy_type, options, monkeypatch):
    """benchmarks/train_baseline.sh's STATE_INPUT=off: the compact preset's inputs less observation.state; the
    hand-frame preset, whose policy type this package registers (a lerobot-train process of its own finds it through
    the plugin in tests/dataset_tools/test_frame_cache.py), with its time input (a feature no dataset holds; the
    policy without it trains and acts in tests/policies), its ResNet group-normalised and the prompt input (the
    dataset's `task` in training, the env's `task_description` when acting) from the command line."""
    preset = json.loads(preset_path(name).read_text())
    preset["policy"]["input_features"].pop("observation.state", None)
    for feature in preset["policy"]["input_features"].values():
        feature["shape"] = [3, *TINY]
    (tmp_path / "preset.json").write_text(json.dumps(preset))
    _lerobot_train_in_this_process(
        monkeypatch, f"--config_path={tmp_path / 'preset.json'}", "--dataset.repo_id=local/tiny",
        f"--dataset.root={dataset_root}", "--env.task=conditional_pick", "--policy.device=cpu",
        "--policy.dim_model=32", "--policy.dim_feedforward=64", "--policy.n_heads=2", "--steps=2", "--save_freq=2",
        "--batch_size=2", "--num_workers=0", f"--output_dir={tmp_path / 'train'}",
        *(f"--policy.{key}={str(value).lower() if isinstance(value, bool) else value}"  # draccus: true, not True
          for key, value in options.items()))
    checkpoint = tmp_path / "train" / "checkpoints" / "last" / "pretrained_model"
    config = json.loads((checkpoint / "config.json").read_text())
    assert config["type"] == policy_type and "observation.state" not in config["input_features"]
    assert config.get("time_input", False) is (policy_type == "act_hand_relative")
    assert {key: config[key] for key in options} == options
    _one_short_episode(checkpoint, tmp_path / "eval")


def test_a_hand_frame_diffusion_preset_trains_and_tavis_eval_runs_it(dataset_root, tmp_path, monkeypatch):
    """`diffusion_hand_relative`, registered by this package (found by lerobot-train as the hand-frame ACT is), with its
    time input (a feature no dataset holds) and the prompt input: a few steps on the tiny dataset (its cameras at
    their size, one shared image encoder), then one short episode."""
    preset = json.loads(preset_path("diffusion_hand_relative_head_wrist_compact").read_text())
    for feature in preset["policy"]["input_features"].values():
        if feature["type"] == "VISUAL":
            feature["shape"] = [3, *TINY]
    (tmp_path / "preset.json").write_text(json.dumps(preset))
    _lerobot_train_in_this_process(
        monkeypatch, f"--config_path={tmp_path / 'preset.json'}", "--dataset.repo_id=local/tiny",
        f"--dataset.root={dataset_root}", *SMALL_RUN, "--policy.use_separate_rgb_encoder_per_camera=false",
        "--policy.prompt_input=true", "--steps=2", "--save_freq=2", "--batch_size=2", "--num_workers=0",
        f"--output_dir={tmp_path / 'train'}")
    checkpoint = tmp_path / "train" / "checkpoints" / "last" / "pretrained_model"
    config = json.loads((checkpoint / "config.json").read_text())
    assert (config["type"], config["time_input"], config["state_input"]) == ("diffusion_hand_relative", True, "none")
    assert config["prompt_input"] and config["input_features"]["observation.environment_state"]["shape"] == [
        1 + len(config["prompts"])]
    _one_short_episode(checkpoint, tmp_path / "eval")


def test_pi0_presets_say_clearly_what_is_missing_offline(tmp_path):
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "HF_HOME": str(tmp_path / "hf"), "HF_TOKEN": ""}
    dataset = _dataset_info(tmp_path / "dataset", ("head",), (224, 224))  # checked first: need only look like one
    result = subprocess.run([sys.executable, "-m", "lerobot_tavis.cli", "train", "pi0_head_only", "--steps=1",
                             f"--dataset.root={dataset}"],
                            capture_output=True, text=True, env=env, timeout=120)
    assert result.returncode == 1
    assert "tavis train: error: pi0 needs lerobot/pi0_base" in result.stderr
    assert "google/paligemma-3b-pt-224" in result.stderr


def _dataset_info(root, cameras, size):
    """A dataset's meta/info.json alone: what `tavis train` reads of it."""
    (root / "meta").mkdir(parents=True)
    features = {f"observation.images.{camera}": {"dtype": "video", "shape": [*size, 3]} for camera in cameras}
    (root / "meta" / "info.json").write_text(json.dumps({"features": features}))
    return root


@pytest.mark.parametrize(("preset", "cameras", "size", "refused"), [
    ("act_head_wrist_compact", ("head", "left_wrist", "right_wrist"), (96, 128),
     "the dataset's head images are 96x128, the policy's input_features say 120x160 (and evaluation renders that): "
     "convert the dataset with --image-size 120x160"),
    ("act_hand_relative_fixed_wrist_compact", ("head", "left_wrist", "right_wrist"), (120, 160),
     "the policy reads the cameras fixed, left_wrist, right_wrist, the dataset has head, left_wrist, right_wrist: "
     "convert the dataset with --cameras fixed,left_wrist,right_wrist"),
    ("diffusion_head_wrist", ("head", "fixed", "left_wrist", "right_wrist"), (480, 640), None),  # resizes its images
    ("act_head_wrist_compact", ("head", "fixed", "left_wrist", "right_wrist"), (120, 160), None),
])
def test_tavis_train_checks_the_datasets_cameras_and_image_size_first(tmp_path, monkeypatch, preset, cameras, size,
                                                                        refused):
    import subprocess as processes

    root = _dataset_info(tmp_path / "dataset", cameras, size)
    started = []
    monkeypatch.setattr(processes, "call", lambda command: started.append(command) or 0)
    if refused is None:
        with pytest.raises(SystemExit) as done:
            main(["train", preset, f"--dataset.root={root}"])
        assert done.value.code == 0 and len(started) == 1
        return
    with pytest.raises(SystemExit, match=f"^tavis train: error: {re.escape(refused)}"):
        main(["train", preset, "--dataset.root", str(root)])
    assert started == []


def test_presets_command_lists_and_locates(capsys):
    main(["presets"])
    assert capsys.readouterr().out.split() == preset_names()
    main(["presets", "pi0_fixed_wrist"])
    assert capsys.readouterr().out.strip() == str(preset_path("pi0_fixed_wrist"))


def _lerobot_train_in_this_process(monkeypatch, *arguments: str) -> None:
    """lerobot-train's console-script entry point with `arguments`, in this process (its own process, which finds
    the plugin as LeRobot does, is the diffusion preset's test above)."""
    from lerobot.scripts import lerobot_train

    monkeypatch.setattr("sys.argv", ["lerobot-train", *arguments])
    monkeypatch.setenv("MUJOCO_GL", "egl")
    lerobot_train.main()


def _one_short_episode(checkpoint, out) -> None:
    """`tavis eval` (in this process) plays one one-second conditional_pick episode with `checkpoint` on CPU and
    reports it."""
    main(["eval", "--policy", str(checkpoint), "--device", "cpu", "--tasks", "conditional_pick", "--splits", "id",
          "--episodes", "1", "--workers", "1", "--batch-size", "1", "--episode-length-s", "1", "--film-episodes", "0",
          "--out", str(out)])
    (cell,) = json.loads((out / "results.json").read_text())["cells"]
    assert (cell["task"], cell["n"]) == ("conditional_pick", 1)
