"""`--env.type=tavis` as LeRobot uses it: registry, features, create_envs (sync and forkserver async), seeds."""

import json
import os
import sys
import types
import warnings
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import draccus
import gymnasium as gym
import numpy as np
import pytest
from lerobot.envs import utils as lerobot_env_utils
from lerobot.envs.configs import EnvConfig
from lerobot.envs.utils import preprocess_observation

import lerobot_env_tavis  # noqa: F401  (registers the env type, as LeRobot's CLIs do)
from lerobot_tavis import canonical
from lerobot_tavis.envs.env import scene_seed
from lerobot_tavis.envs.tasks.catalog import suite_tasks
from lerobot_tavis.envs.vector import NEW_ROLLOUT_OPTION, FreezeAfterEpisodeEnd, LazyAsyncVectorEnv
from lerobot_tavis.eval.env_config import TavisEnvConfig, expand_tasks
from lerobot_tavis.eval.episode_log import EpisodeLogger


def test_every_registered_env_type_is_default_constructible():
    """What LeRobot's own registry test does, with the plugin loaded."""
    for name in EnvConfig.get_known_choices():
        assert EnvConfig.get_choice_class(name)().type == name
    config = EnvConfig.get_choice_class("tavis")()
    assert isinstance(config, TavisEnvConfig) and config.task == "tavis_head" and config.fps == 20


@pytest.mark.parametrize("mode,cameras", [("head_only", ["head"]),
                                          ("fixed_wrist", ["fixed", "left_wrist", "right_wrist"])])
def test_features_follow_the_camera_mode(mode, cameras):
    config = TavisEnvConfig(camera_mode=mode, image_size=(240, 320))
    images = {k: v for k, v in config.features.items() if k.startswith("pixels/")}
    assert sorted(images) == sorted(f"pixels/{c}" for c in cameras)
    assert all(f.shape == (240, 320, 3) for f in images.values())
    assert config.features_map["pixels/" + cameras[0]] == f"observation.images.{cameras[0]}"
    assert config.features_map["agent_pos"] == "observation.state"
    assert config.features["action"].shape == (19,)


def test_task_spec_expands_to_suites():
    assert expand_tasks("tavis_hands") == {"tavis_hands": ["peeking_box", "occluded_reach",
                                                           "blocked_clutter_pick_cube"]}
    assert expand_tasks("wait_then_act, peeking_box,conditional_pick") == {
        "tavis_head": ["wait_then_act", "conditional_pick"], "tavis_hands": ["peeking_box"]}


@pytest.mark.parametrize("kwargs,message", [({"task": "tavis_legs"}, "task must be one of"),
                                            ({"robot": "spot"}, "robot must be one of"),
                                            ({"camera_mode": "eye"}, "camera_mode must be one of"),
                                            ({"split": "ood"}, "split must be one of")])
def test_bad_config_values_are_rejected(kwargs, message):
    from lerobot_tavis.errors import FieldError

    with pytest.raises(ValueError, match=message) as error:  # what lerobot-train / lerobot-eval see
        TavisEnvConfig(**kwargs)
    assert isinstance(error.value, FieldError) and error.value.field == next(iter(kwargs))


def test_sync_create_envs_wraps_every_sub_env_and_runs():
    config = TavisEnvConfig(task="tavis_hands", image_size=(24, 32), camera_mode="head_wrist")
    envs = config.create_envs(n_envs=2, use_async_envs=False)
    assert list(envs) == ["tavis_hands"] and list(envs["tavis_hands"]) == [0, 1, 2]
    vec = envs["tavis_hands"][1]
    assert all(isinstance(e, FreezeAfterEpisodeEnd) for e in vec.envs)
    obs, info = vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
    batch = preprocess_observation(obs)
    assert batch["observation.images.head"].shape == (2, 3, 24, 32)
    assert batch["observation.state"].shape == (2, 19)
    assert list(vec.call("task")) == ["occluded_reach"] * 2
    vec.step(np.tile(canonical.rest_action(), (2, 1)))
    for vecs in envs.values():
        for v in vecs.values():
            v.close()


def test_each_task_keeps_its_index_in_its_suite_whatever_else_runs():
    """lerobot-eval files a task's videos and results under `<suite>_<task_id>`: one task alone goes where the
    same task of a whole suite's run goes."""
    ids = {suite: list(factories) for suite, factories in TavisEnvConfig(
        task="multi_shelf_scan,occluded_reach,wait_then_act").sub_env_factories().items()}
    assert ids == {"tavis_head": [4, 1], "tavis_hands": [1]}
    whole = TavisEnvConfig(task="tavis_head").sub_env_factories()["tavis_head"]
    assert [factory.args[0] for factory in whole.values()] == list(suite_tasks("tavis_head"))
    assert [factory.keywords["task_id"] for factory in whole.values()] == list(whole)


def test_async_create_envs_run_in_lean_forkserver_workers(tmp_path, monkeypatch):
    """The workers import neither torch nor LeRobot, nor the main script of the process that starts them (under
    lerobot-eval, LeRobot's: multiprocessing would have each worker import it, and torch with it)."""
    script = tmp_path / "main_script.py"
    script.write_text(f"import pathlib\npathlib.Path({str(tmp_path / 'imported')!r}).touch()\n")
    main = types.ModuleType("__main__")
    main.__file__, main.__spec__ = str(script), None
    monkeypatch.setitem(sys.modules, "__main__", main)
    config = TavisEnvConfig(task="wait_then_act", image_size=(24, 32))
    vec = config.create_envs(n_envs=2, use_async_envs=True)["tavis_head"][1]
    assert isinstance(vec, LazyAsyncVectorEnv)
    obs, _ = vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
    assert obs["pixels"]["head"].shape == (2, 24, 32, 3)
    obs, reward, terminated, truncated, info = vec.step(np.tile(canonical.rest_action(), (2, 1)))
    assert obs["agent_pos"].shape == (2, 19)
    workers = [process.pid for process in vec._started().processes]
    mapped = [Path(f"/proc/{pid}/maps").read_text() for pid in workers]
    vec.close()
    assert len(mapped) == 2 and not any("libtorch" in maps or "/lerobot/" in maps for maps in mapped)
    assert not (tmp_path / "imported").exists()
    assert main.__file__ == str(script) and main.__spec__ is None  # as it was


def test_only_the_filmed_sub_envs_of_an_async_batch_draw_frames():
    """lerobot-eval asks every async sub-env for a frame each step: only the first `filmed_envs` draw one, and only
    theirs come back, so that lerobot-eval films as many episodes."""
    config = TavisEnvConfig(task="wait_then_act", image_size=(24, 32), filmed_envs=1)
    vec = config.create_envs(n_envs=3, use_async_envs=True)["tavis_head"][1]
    vec.reset(seed=[1000, 1001, 1002], options={NEW_ROLLOUT_OPTION: True})
    frames = vec.call("render")
    unfilmed = vec._started().call("render")[1:]
    vec.close()
    assert len(frames) == 1
    assert frames[0].ndim == 3 and frames[0].dtype == np.uint8 and frames[0].shape[0] > 24  # overview + views
    assert unfilmed == (None, None)  # drawn by nobody


def test_an_async_batch_asks_its_workers_for_the_prompts_once_per_reset():
    """lerobot-eval asks for every sub-env's task_description at each step; the answer changes only at a reset."""
    config = TavisEnvConfig(task="conditional_pick", image_size=(24, 32))
    vec = config.create_envs(n_envs=2, use_async_envs=True)["tavis_head"][0]
    vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
    workers = vec._started()
    asked, ask_workers = [], workers.call

    def counted(name, *args, **kwargs):
        asked.append(name)
        return ask_workers(name, *args, **kwargs)

    workers.call = counted
    try:
        first = vec.call("task_description")
        vec.step(np.tile(canonical.rest_action(), (2, 1)))
        assert vec.call("task_description") == first == ask_workers("task_description")
        assert asked == ["task_description"]
        vec.reset(seed=[1002, 1003], options={NEW_ROLLOUT_OPTION: True})
        assert vec.call("task_description") == ask_workers("task_description")
        assert asked == ["task_description"] * 2
        assert len(first) == 2 and all(prompt.startswith("Look at the card") for prompt in first)
    finally:
        vec.close()


@pytest.mark.parametrize("worker_niceness", [3, 0])
def test_async_workers_run_at_the_given_niceness_above_this_process(worker_niceness):
    """Each worker process adds `worker_niceness` to the niceness it inherits (as `nice`); 0 leaves it equal. This
    process keeps its own, though gymnasium's AsyncVectorEnv calls the first sub-env factory here too."""
    own_niceness = os.nice(0)
    probe = gym.make("CartPole-v1")  # tiny, and picklable by reference to gymnasium
    vec = LazyAsyncVectorEnv([partial(gym.make, "CartPole-v1")] * 2, probe.observation_space, probe.action_space,
                             probe.metadata, worker_niceness=worker_niceness)
    try:
        vec.reset(seed=0)
        workers = [os.getpriority(os.PRIO_PROCESS, process.pid) for process in vec._started().processes]
    finally:
        vec.close()
    assert os.nice(0) == own_niceness
    assert workers == [own_niceness + worker_niceness] * 2


def test_retargeted_workers_build_the_new_task_in_the_same_processes():
    """`retarget` swaps every started worker's sub-env for the new task's, in the same process and at the same
    niceness; its episodes are those of a new batch of that task (built in this process: same seeds, same pixels)."""
    fresh = TavisEnvConfig(task="conditional_pick", image_size=(24, 32)).create_envs(2, False)["tavis_head"][0]
    expected, _ = fresh.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
    fresh.close()
    vec = TavisEnvConfig(task="wait_then_act", image_size=(24, 32), worker_niceness=3,
                         filmed_envs=2).create_envs(2, True)["tavis_head"][1]
    try:
        vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
        workers = [process.pid for process in vec._started().processes]
        niceness = [os.getpriority(os.PRIO_PROCESS, pid) for pid in workers]
        factory = TavisEnvConfig(task="conditional_pick", image_size=(24, 32)).sub_env_factories()["tavis_head"][0]
        with pytest.raises(ValueError, match="3 sub-env factories for a batch of 2"):
            vec.retarget([factory] * 3, filmed_envs=1)
        vec.retarget([factory] * 2, filmed_envs=1)
        observation, _ = vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
        assert [process.pid for process in vec._started().processes] == workers
        assert [os.getpriority(os.PRIO_PROCESS, pid) for pid in workers] == niceness
        assert vec.call("task") == ("conditional_pick", "conditional_pick")
        assert len(vec.call("render")) == 1 and vec._started().call("render")[1] is None
        for camera, images in expected["pixels"].items():
            assert np.array_equal(observation["pixels"][camera], images), camera
        assert np.array_equal(observation["agent_pos"], expected["agent_pos"])
    finally:
        vec.close()


def test_a_retarget_that_fails_in_the_workers_raises_at_the_next_use():
    """`retarget` does not wait for the workers; their error comes with the next reset, naming what was wrong."""
    from lerobot_tavis.errors import FieldError
    from lerobot_tavis.eval.env_factory import make_tavis_env

    vec = TavisEnvConfig(task="wait_then_act", image_size=(24, 32)).create_envs(2, True)["tavis_head"][1]
    try:
        vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
        broken = partial(make_tavis_env, "conditional_pick", "gr1t2", "head_wrist", "no_split", (24, 32), 20.0)
        vec.retarget([broken] * 2, filmed_envs=0)
        with (pytest.raises(FieldError, match="split must be one of"),  # the worker's error, type and message
              warnings.catch_warnings(record=True) as reported):
            warnings.simplefilter("always")
            vec.reset(seed=[1000, 1001], options={NEW_ROLLOUT_OPTION: True})
        # gymnasium also reports a worker's error, with its traceback, as warnings
        assert "Received the following error from Worker" in str(reported[0].message)
        assert all("ERROR" in str(warning.message) for warning in reported)
    finally:
        vec.close()


def test_a_negative_filmed_env_count_is_refused():
    with pytest.raises(ValueError, match="filmed_envs must be an integer >= 0"):
        TavisEnvConfig(filmed_envs=-1)


@pytest.mark.parametrize("worker_niceness", [-1, 20])
def test_a_worker_niceness_outside_0_to_19_is_refused(worker_niceness):
    from lerobot_tavis.errors import FieldError

    with pytest.raises(ValueError, match="worker_niceness must be an integer from 0 to 19") as error:
        TavisEnvConfig(worker_niceness=worker_niceness)
    assert isinstance(error.value, FieldError) and error.value.field == "worker_niceness"


def test_the_new_rollout_option_is_lerobots():
    assert NEW_ROLLOUT_OPTION == lerobot_env_utils.NEW_ROLLOUT_OPTION


def test_tasks_given_the_same_seed_get_their_own_scene():
    assert scene_seed(1000, "clutter_pick_cube") != scene_seed(1000, "blocked_clutter_pick_cube")
    assert scene_seed(1000, "clutter_pick_cube") == scene_seed(1000, "clutter_pick_cube")


def _episode_log_of(config: TavisEnvConfig):
    """The path the episode log of create_envs' first sub-env writes to, or None without one."""
    (vec,) = config.create_envs(n_envs=1)["tavis_head"].values()
    env = vec.envs[0]
    while not isinstance(env, EpisodeLogger) and hasattr(env, "env"):
        env = env.env
    vec.close()
    return env.path if isinstance(env, EpisodeLogger) else None


@pytest.mark.parametrize("argv", [["--output_dir=OUT"], ["--output_dir", "OUT"]])
def test_plain_lerobot_eval_logs_beside_the_output_dir_of_its_command_line(tmp_path, monkeypatch, argv):
    argv = [arg.replace("OUT", str(tmp_path / "run")) for arg in argv]
    monkeypatch.setattr("sys.argv", ["lerobot-eval", "--env.type=tavis", *argv])
    assert _episode_log_of(TavisEnvConfig(task="wait_then_act")) == tmp_path / "run" / "episodes.jsonl"


def test_an_explicit_episode_log_wins_and_without_either_there_is_none(tmp_path, monkeypatch, caplog):
    monkeypatch.setattr("sys.argv", ["lerobot-eval", f"--output_dir={tmp_path / 'run'}"])
    config = TavisEnvConfig(task="wait_then_act", episode_log=str(tmp_path / "mine.jsonl"))
    assert _episode_log_of(config) == tmp_path / "mine.jsonl"
    monkeypatch.setattr("sys.argv", ["lerobot-eval", "--env.type=tavis"])
    assert _episode_log_of(TavisEnvConfig(task="wait_then_act")) is None
    assert "no episode log" in caplog.text and "--env.episode_log" in caplog.text


def _checkpoint(path, cameras=("head", "left_wrist", "right_wrist"), image_size=(120, 160), env=None,
                policy_type="act"):
    """A checkpoint's config files (no weights): its `policy_type` policy reads `cameras` at `image_size`."""
    import json

    path.mkdir(parents=True)
    images = {f"observation.images.{camera}": {"type": "VISUAL", "shape": [3, *image_size]} for camera in cameras}
    (path / "config.json").write_text(json.dumps({"type": policy_type, "input_features": images}))
    if env is not None:
        (path / "train_config.json").write_text(json.dumps({"env": env}))
    return str(path)


def test_lerobot_eval_renders_what_the_policy_of_its_command_line_reads(tmp_path, caplog):
    """`lerobot-eval --policy.path=<checkpoint> --env.type=tavis`: settings left out take the checkpoint's."""
    checkpoint = _checkpoint(tmp_path / "ckpt", ("fixed", "left_wrist", "right_wrist"), (96, 128),
                             env={"type": "tavis", "robot": "reachy2", "camera_mode": "fixed_wrist"})
    config = TavisEnvConfig(task="wait_then_act")
    with caplog.at_level("INFO"):
        config.match_command_line_policy([f"--policy.path={checkpoint}", "--env.type=tavis"])
    assert (config.robot, config.camera_mode, tuple(config.image_size)) == ("reachy2", "fixed_wrist", (96, 128))
    assert config.features["pixels/fixed"].shape == (96, 128, 3) and "pixels/head" not in config.features
    assert "the env takes the checkpoint's robot reachy2, camera_mode fixed_wrist, image_size 96x128" in caplog.text


def test_a_setting_given_to_lerobot_eval_wins_with_a_warning(tmp_path, caplog):
    checkpoint = _checkpoint(tmp_path / "ckpt", policy_type="diffusion")  # resizes its images itself
    config = TavisEnvConfig(task="wait_then_act", image_size=(480, 640))  # the default, but on the command line
    with caplog.at_level("WARNING"):
        config.match_command_line_policy([f"--policy.path={checkpoint}", "--env.image_size=[480, 640]"])
    assert tuple(config.image_size) == (480, 640)
    assert ("the policy was trained on 120x160 images; --env.image_size asks for 480x640 (leave --env.image_size "
            "out to use the checkpoint's)") in caplog.text


def test_lerobot_eval_refuses_another_image_size_for_a_policy_that_does_not_resize(tmp_path):
    checkpoint = _checkpoint(tmp_path / "ckpt", policy_type="act")
    config = TavisEnvConfig(task="wait_then_act", image_size=(96, 128))
    with pytest.raises(ValueError, match=r"^the policy \(act, which does not resize its images\) was trained on "
                                         "120x160 images, --env.image_size asks for 96x128: leave --env.image_size "
                                         "out to use the checkpoint's$"):
        config.match_command_line_policy([f"--policy.path={checkpoint}"])


def test_lerobot_eval_refuses_a_camera_mode_without_the_policys_cameras(tmp_path):
    checkpoint = _checkpoint(tmp_path / "ckpt")
    config = TavisEnvConfig(task="wait_then_act", camera_mode="fixed_only")
    with pytest.raises(ValueError, match="the policy reads the cameras head, left_wrist, right_wrist, camera mode "
                                         "fixed_only renders fixed: use --env.camera_mode head_wrist"):
        config.match_command_line_policy([f"--policy.path={checkpoint}"])


def test_without_a_policy_on_the_command_line_the_settings_stay(tmp_path):
    config = TavisEnvConfig(task="wait_then_act", image_size=(24, 32))
    config.match_command_line_policy(["--env.type=tavis"])
    assert tuple(config.image_size) == (24, 32)


@dataclass
class _Cli:
    env: EnvConfig


@pytest.mark.parametrize("args,shadows", [([], True), (["--env.shadows=false"], False)])
def test_shadows_are_on_unless_the_command_line_turns_them_off_and_the_log_says_which(tmp_path, args, shadows):
    config = draccus.parse(_Cli, args=["--env.type=tavis", "--env.task=wait_then_act", "--env.camera_mode=fixed_only",
                                       "--env.image_size=[16,16]", "--env.episode_length_s=0.1",
                                       f"--env.episode_log={tmp_path / 'episodes.jsonl'}", *args]).env
    assert config.shadows is shadows
    (vec,) = config.create_envs(n_envs=1)["tavis_head"].values()
    vec.reset(seed=[0], options={NEW_ROLLOUT_OPTION: True})
    assert vec.envs[0].unwrapped.shadows is shadows
    model = vec.envs[0].unwrapped.model
    assert bool(model.light_castshadow.any()) is shadows
    for _ in range(2):
        vec.step(canonical.rest_action()[None])
    vec.close()
    (record,) = [json.loads(line) for line in (tmp_path / "episodes.jsonl").read_text().splitlines()]
    assert record["shadows"] is shadows
