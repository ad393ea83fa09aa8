"""Every bad input is one clear line naming the option or field: a non-zero exit of the `tavis` command, no output
folder left behind, and a ValueError from the env, its config and the canonical action check."""

import os
import subprocess
import sys

import numpy as np
import pytest

from lerobot_tavis import canonical, checks
from lerobot_tavis.cli import main

from .conftest import refused_line as _refused
from lerobot_tavis.errors import FieldError, InputError, PathExistsError, PathNotFoundError, TavisError

REPO_ID = "must be <owner>/<name> on the Hugging Face Hub"




@pytest.mark.parametrize("argv,message", [
    (["eval", "--expert", "--image-size", "abc"], "tavis eval: error: --image-size must be HxW in pixels"),
    (["eval", "--expert", "--image-size", "0x64"], "tavis eval: error: --image-size must be HxW"),
    (["eval", "--expert", "--image-size", "8x8"], "tavis eval: error: --image-size must be within 16..4096 pixels"),
    (["eval", "--expert", "--episodes", "0"], "tavis eval: error: --episodes must be an integer >= 1, got 0"),
    (["eval", "--expert", "--seed", "-1"], "tavis eval: error: --seed must be an integer >= 0, got -1"),
    (["eval", "--expert", "--workers", "0"], "tavis eval: error: --workers must be an integer >= 1, got 0"),
    (["eval", "--expert", "--batch-size", "0"], "tavis eval: error: --batch-size must be an integer >= 1, got 0"),
    (["record", "--workers", "0"], "tavis record: error: --workers must be an integer >= 1, got 0"),
    (["record", "--seed-start", "-5"], "tavis record: error: --seed-start must be an integer >= 0, got -5"),
    (["record", "--episodes-per-task", "0"], "tavis record: error: --episodes-per-task must be an integer >= 1"),
    (["demo", "--seed", "-1"], "tavis demo: error: --seed must be an integer >= 0, got -1"),
    (["gallery", "--seed", "-1"], "tavis gallery: error: --seed must be an integer >= 0, got -1"),
    (["gallery", "--image-size", "240"], "tavis gallery: error: --image-size must be HxW"),
])
def test_bad_options_exit_with_one_line_and_create_nothing(tmp_path, argv, message):
    out = tmp_path / "out"
    assert _refused([*argv, "--out", str(out)]).startswith(message)
    assert not out.exists()


@pytest.mark.parametrize("repo_id", ["noslash", "a/b/c", "", "/name", "owner/", "a//b", "own er/name", "a/../b",
                                     "-a/b", "a/b.", "a--b/c", "ówner/name"])
def test_repo_ids_must_be_owner_slash_name(tmp_path, repo_id):
    root = tmp_path / "dataset"
    raw = tmp_path / "raw"
    assert _refused(["convert", str(raw), f"--repo-id={repo_id}", "--root", str(root)]).startswith(
        f"tavis convert: error: --repo-id {REPO_ID}")
    assert _refused(["convert", "--from-tavis", str(raw), f"--repo-id={repo_id}", "--root", str(root)]).startswith(
        f"tavis convert: error: --repo-id {REPO_ID}")
    assert _refused(["push", str(root), f"--repo-id={repo_id}"]).startswith(f"tavis push: error: --repo-id {REPO_ID}")
    assert _refused(["pull", "--root", str(root), "--", repo_id]).startswith(f"tavis pull: error: repo_id {REPO_ID}")
    assert repr(repo_id) in _refused(["pull", "--root", str(root), "--", repo_id])
    assert not root.exists()


@pytest.mark.parametrize("repo_id", ["local/x", "someone/tavis_toy", "Org-1/tavis-head-gr1t2.v2", "a/b"])
def test_hub_valid_repo_ids_are_accepted(repo_id):
    assert checks.repo_id(repo_id) == repo_id


def test_convert_refuses_zero_workers_before_reading_anything(tmp_path):
    root = tmp_path / "dataset"
    assert _refused(["convert", str(tmp_path / "raw"), "--repo-id", "local/x", "--root", str(root), "--workers",
                     "0"]) == "tavis convert: error: --workers must be an integer >= 1, got 0"
    assert not root.exists()


def test_a_bad_image_size_is_one_line_on_stderr_without_traceback(tmp_path):
    out = tmp_path / "out"
    env = {**os.environ, "MUJOCO_GL": "egl"}
    result = subprocess.run([sys.executable, "-m", "lerobot_tavis.cli", "eval", "--expert", "--image-size", "abc",
                             "--out", str(out)], capture_output=True, text=True, env=env, timeout=120)
    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    assert result.stderr.splitlines() == [
        "tavis eval: error: --image-size must be HxW in pixels, e.g. 480x640 (height x width), got 'abc'"]
    assert not out.exists()


@pytest.mark.parametrize("content,problem", [
    ("{not json", "not a JSON file (Expecting property name enclosed in double quotes: line 1, column 2)"),
    ("[1, 2]", "not a lerobot-eval eval_info.json"),
    ('{"overall": {}}', "not a lerobot-eval eval_info.json"),
    ('{"per_task": [{"task_group": "tavis_head", "task_id": 0}]}', "not a lerobot-eval eval_info.json"),
])
def test_a_malformed_eval_info_is_reported_with_its_file_name(tmp_path, content, problem):
    cell = tmp_path / "tavis_head__id"
    cell.mkdir()
    (cell / "eval_info.json").write_text(content)
    (cell / "episodes.jsonl").write_text("")
    message = _refused(["report", str(tmp_path)])
    assert message.startswith(f"tavis report: error: {cell / 'eval_info.json'}: {problem}")
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["episodes.jsonl", "eval_info.json", "tavis_head__id"]


@pytest.mark.parametrize("line,problem", [
    ("{not json", "not a JSON line"),
    ('{"suite": "tavis_head", "task_id": 0}', "not an episode record (missing robot, task, split, camera_mode, seed, "
                                             "success)"),
    ("[1]", "not an episode record"),
])
def test_a_damaged_episode_log_line_is_reported_with_its_place(tmp_path, line, problem):
    cell = tmp_path / "tavis_head__id"
    cell.mkdir()
    (cell / "eval_info.json").write_text(
        '{"per_task": [{"task_group": "tavis_head", "task_id": 0, "metrics": {"successes": [true]}}]}')
    (cell / "episodes.jsonl").write_text(line + "\n")
    message = _refused(["report", str(tmp_path)])
    assert message.startswith(f"tavis report: error: {cell / 'episodes.jsonl'}:1: {problem}")


@pytest.mark.parametrize("kwargs,message", [
    ({"episode_length_s": float("inf")}, "episode_length_s must be a finite number of seconds, at least one step "
                                         "at 20 fps (0.05 s), got inf"),
    ({"episode_length_s": float("nan")}, "episode_length_s must be a finite number of seconds"),
    ({"episode_length_s": "20"}, "episode_length_s must be a finite number of seconds"),
    ({"episode_length_s": 0.01}, "episode_length_s must be a finite number of seconds, at least one step at 20 fps"),
    ({"episode_length_s": -1.0}, "episode_length_s must be a finite number of seconds"),
    ({"image_size": (48.5, 64)}, "image_size must be (height, width), two positive integers (pixels), got (48.5, 64)"),
    ({"image_size": ("48", "64")}, "image_size must be (height, width), two positive integers"),
    ({"image_size": "480x640"}, "image_size must be (height, width), two positive integers"),
    ({"image_size": (48, 64, 3)}, "image_size must be (height, width), two positive integers"),
    ({"image_size": (0, 64)}, "image_size must be within 16..4096 pixels per side"),
])
def test_env_and_env_config_name_the_bad_field(kwargs, message):
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.eval.env_config import TavisEnvConfig

    with pytest.raises(ValueError) as env_error:
        TavisEnv("conditional_pick", **kwargs)
    assert str(env_error.value).startswith(message)
    with pytest.raises(ValueError) as config_error:
        TavisEnvConfig(task="conditional_pick", **kwargs)
    assert str(config_error.value).startswith(message)


def test_the_env_keeps_good_sizes_and_lengths():
    from lerobot_tavis.envs.env import TavisEnv

    env = TavisEnv("conditional_pick", image_size=(np.int64(48), 64.0), episode_length_s=0.05, fps=20)
    assert env.image_size == (48, 64) and all(type(side) is int for side in env.image_size)
    assert env._max_episode_steps == 1
    assert TavisEnv("conditional_pick", episode_length_s=np.float32(1.5))._max_episode_steps == 30


@pytest.mark.parametrize("action,message", [
    (canonical.rest_action() + 0.5j, "action must be real numbers, got complex values"),
    (list(canonical.rest_action()[:-1]) + [1j], "action must be real numbers, got complex values"),
    ({"left_ee_x": 0.3}, "action must be an array of 19 numbers, got dict"),
    ("rest", "action must be an array of 19 numbers, got str"),
    (None, "action must be an array of 19 numbers, got NoneType"),
    ([[0.0] * 19, [0.0]], "action must be an array of 19 numbers, got list"),
    ([0.0] * 18 + ["1"], "action must be an array of 19 numbers, got list"),
])
@pytest.mark.filterwarnings("error")  # no ComplexWarning: the imaginary part is never dropped
def test_actions_that_are_not_19_real_numbers_are_refused(action, message):
    with pytest.raises(ValueError) as error:
        canonical.validate_action(action)
    assert str(error.value).startswith(message)


@pytest.mark.filterwarnings("error")
def test_real_actions_of_any_numeric_type_are_accepted():
    rest = canonical.rest_action()
    for action in (rest, rest.astype(np.float32), list(rest), tuple(rest), rest.astype(object)):
        np.testing.assert_allclose(canonical.validate_action(action), rest, rtol=1e-6)


def _command_raising(error: BaseException):
    def run(args):
        raise error
    return run


@pytest.mark.parametrize("error,message", [
    (InputError("the input is bad"), "the input is bad"),
    (FieldError("workers", "must be an integer >= 1, got 0"), "--workers must be an integer >= 1, got 0"),
    (PathNotFoundError("/data/raw not found"), "/data/raw not found"),
    (PathExistsError("/data/out already exists"), "/data/out already exists"),
    (TavisError("cannot reach the Hub"), "cannot reach the Hub"),
])
def test_an_error_of_the_family_is_one_line(monkeypatch, tmp_path, error, message):
    from lerobot_tavis import cli

    monkeypatch.setattr(cli, "_report", _command_raising(error))
    assert _refused(["report", str(tmp_path)]) == f"tavis report: error: {message}"


@pytest.mark.parametrize("bug", [ValueError("operands could not be broadcast together"), FileNotFoundError("/tmp/x"),
                                 FileExistsError("/tmp/y"), KeyError("seed"), RuntimeError("internal")])
def test_any_other_error_inside_a_command_propagates(monkeypatch, tmp_path, bug):
    from lerobot_tavis import cli

    monkeypatch.setattr(cli, "_report", _command_raising(bug))
    with pytest.raises(type(bug)) as raised:
        main(["report", str(tmp_path)])
    assert raised.value is bug  # not turned into a one-line exit


def test_the_family_keeps_the_builtin_exceptions_it_replaced():
    assert issubclass(FieldError, InputError) and issubclass(InputError, ValueError)
    assert issubclass(PathNotFoundError, FileNotFoundError) and issubclass(PathExistsError, FileExistsError)
    assert all(issubclass(cls, TavisError) for cls in (FieldError, InputError, PathNotFoundError, PathExistsError))


def test_a_missing_eval_dir_is_one_line_without_traceback(tmp_path):
    result = subprocess.run([sys.executable, "-m", "lerobot_tavis.cli", "report", str(tmp_path)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 1
    assert result.stderr.splitlines() == [f"tavis report: error: no eval_info.json under {tmp_path}"]


def test_a_bug_inside_a_command_keeps_its_traceback(tmp_path):
    code = ("import sys; from lerobot_tavis import cli\n"
            "def bug(args): raise ValueError('a bug, not the user')\n"
            "cli._report = bug\n"
            "cli.main(sys.argv[1:])\n")
    result = subprocess.run([sys.executable, "-c", code, "report", str(tmp_path)], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 1
    assert "Traceback" in result.stderr and result.stderr.rstrip().endswith("ValueError: a bug, not the user")
    assert "tavis report: error:" not in result.stderr


def test_user_errors_still_name_the_problem_in_one_line(tmp_path):
    out = tmp_path / "out"
    missing = tmp_path / "no" / "checkpoint"
    assert _refused(["eval", "--policy", str(missing), "--out", str(out)]) == (
        f"tavis eval: error: --policy {missing}: no such checkpoint directory")
    assert _refused(["eval", "--expert", "--image-size", "480by640", "--out", str(out)]).startswith(
        "tavis eval: error: --image-size must be HxW in pixels")
    assert _refused(["record", "--tasks", "tabletop", "--split", "ood_spatial", "--out", str(out)]) == (
        "tavis record: error: --split of task 'tabletop' must be one of ('id',), got 'ood_spatial'")
    assert _refused(["record", "--tasks", "no_such_task", "--out", str(out)]).startswith(
        "tavis record: error: --tasks must be one of [")
    assert not out.exists()


def test_a_checkpoint_folder_without_its_config_is_one_line(tmp_path):
    checkpoint = tmp_path / "pretrained_model"
    checkpoint.mkdir()
    message = _refused(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out")])
    assert message.startswith("tavis eval: error: ") and "config.json" in message and str(checkpoint) in message


def test_a_training_without_its_dataset_is_one_line_before_lerobot_train_starts(tmp_path, monkeypatch):
    monkeypatch.setenv("HF_LEROBOT_HOME", str(tmp_path / "cache"))  # LeRobot's default root: empty
    assert _refused(["train", "diffusion_head_wrist", "--steps=1"]).startswith(
        "tavis train: error: no --dataset.root: pass --dataset.root=")
    empty = tmp_path / "empty"
    empty.mkdir()
    for root in (["--dataset.root", str(empty)], [f"--dataset.root={tmp_path / 'missing'}"]):
        assert _refused(["train", "diffusion_head_wrist", *root]).startswith(
            f"tavis train: error: --dataset.root {root[-1].removeprefix('--dataset.root=')} holds no LeRobotDataset")


def test_a_bad_env_field_in_lerobot_eval_is_one_line(tmp_path):
    lerobot_eval = os.path.join(os.path.dirname(sys.executable), "lerobot-eval")
    result = subprocess.run([lerobot_eval, "--env.type=tavis", "--env.task=conditonal_pick", "--policy.type=diffusion",
                             "--policy.device=cpu", f"--output_dir={tmp_path / 'out'}"],
                            capture_output=True, text=True, timeout=300, env={**os.environ, "HF_HUB_OFFLINE": "1"})
    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    assert result.stderr.splitlines()[-1].startswith("lerobot-eval: error: --env.task must be one of [")
    assert result.stderr.splitlines()[-1].endswith("got 'conditonal_pick'")


def test_other_errors_while_lerobot_parses_keep_their_traceback():
    from draccus.utils import ParsingError

    from lerobot_tavis.lerobot_cli_errors import env_field_error

    def raised(error, cause):
        try:
            raise error from cause
        except ParsingError as caught:
            return caught

    field = FieldError("task", "must be one of [...]")
    assert env_field_error(raised(ParsingError("Couldn't instantiate class TavisEnvConfig"), field)) is field
    assert env_field_error(raised(ParsingError("Couldn't instantiate class TavisEnvConfig"), TypeError("x"))) is None
    assert env_field_error(raised(ParsingError("Couldn't instantiate class DiffusionConfig"), field)) is None
