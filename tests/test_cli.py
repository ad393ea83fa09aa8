"""The `tavis` command's options are its subcommands' dataclasses: every field is an option and every option a
field, a command line parses into the dataclass, and parsing one subcommand imports only what it runs."""

import argparse
import json
import re
import subprocess
import sys
from dataclasses import fields
from pathlib import Path

import pytest

from lerobot_tavis.cli import build_parser
from lerobot_tavis.cli_options import command_fields, from_args, spelling
from lerobot_tavis.envs.tasks.catalog import suite_tasks

# Per subcommand: a command line setting every option, and what the dataclass then holds.
COMMAND_LINES = {
    "demo": (["--out", "films", "--robots", "reachy2", "--tasks", "peeking_box", "wait_then_act", "--image-size",
              "48x64", "--seed", "3"],
             dict(out_dir=Path("films"), robots=("reachy2",), tasks=("peeking_box", "wait_then_act"),
                  image_size=(48, 64), seed=3)),
    "gallery": (["--out", "stills", "--robots", "gr1t2", "--tasks", "conditional_pick", "--image-size", "96 x 128",
                 "--seed", "2"],
                dict(out_dir=Path("stills"), robots=("gr1t2",), tasks=("conditional_pick",), image_size=(96, 128),
                     seed=2)),
    "eval": (["--policy", "me/policy", "--robot", "reachy2", "--suite", "tavis_hands", "tavis_head", "--splits", "id",
              "ood_visual:table", "--episodes", "2", "--camera-mode", "fixed_wrist", "--image-size", "96x128",
              "--batch-size", "2", "--device", "cuda:1", "--episode-length-s", "5.5", "--policy-option", "steps=10",
              "--policy-option", "name=DDIM", "--workers", "3", "--chunk-episodes", "4", "--backend", "ray",
              "--seed", "7", "--out", "evals"],
             dict(policy_path="me/policy", expert=False, robot="reachy2", suites=("tavis_hands", "tavis_head"),
                  splits=("id", "ood_visual:table"), n_episodes=2, camera_mode="fixed_wrist", image_size=(96, 128),
                  batch_size=2, device="cuda:1", episode_length_s=5.5, policy_options=(("steps", 10), ("name", "DDIM")),
                  workers=3, chunk_episodes=4, backend="ray", seed=7, out_dir=Path("evals"))),
    "record": (["--robot", "reachy2", "--suite", "tavis_hands", "--split", "ood_spatial", "--episodes-per-task", "3",
                "--keep-failures", "--seed-start", "5", "--workers", "2", "--backend", "ray", "--out", "raw"],
               dict(robot="reachy2", suite="tavis_hands", tasks=suite_tasks("tavis_hands"), split="ood_spatial",
                    episodes_per_task=3, keep_failures=True, seed_start=5, workers=2, backend="ray",
                    out_dir=Path("raw"))),
    "teleop": (["--task", "peeking_box", "--robot", "reachy2", "--split", "ood_init_pose", "--episodes", "2",
                "--seed-start", "9", "--keep-failures", "--view", "overview", "--gamepad", "--out", "raw"],
               dict(task="peeking_box", robot="reachy2", split="ood_init_pose", episodes=2, seed_start=9,
                    keep_failures=True, view="overview", gamepad=True, out_dir=Path("raw"))),
    "view": (["--task", "peeking_box", "--robot", "reachy2", "--split", "ood_spatial", "--seed", "4", "--policy",
              "ckpt", "--device", "cuda", "--camera", "head"],
             dict(task="peeking_box", robot="reachy2", split="ood_spatial", seed=4, driver="policy", policy="ckpt",
                  device="cuda", camera="head")),
    "convert": (["raw", "--repo-id", "me/tavis", "--root", "dataset", "--fps", "30", "--image-size", "48x64",
                 "--cameras", "head,fixed", "--task", "peeking_box", "--overwrite", "--storage", "png", "--zero-neck",
                 "--workers", "2"],
                dict(raw_dir=Path("raw"), from_tavis=None, repo_id="me/tavis", root=Path("dataset"), fps=30,
                     image_size=(48, 64), cameras=("head", "fixed"), task="peeking_box", overwrite=True,
                     storage="png", zero_neck=True, workers=2)),
    "cache-frames": (["dataset", "--workers", "4", "--video-backend", "torchcodec"],
                     dict(root=Path("dataset"), workers=4, video_backend="torchcodec")),
    "verify-dataset": (["dataset", "--episodes", "1", "2"], dict(root=Path("dataset"), episodes=(1, 2))),
    "noise-state": (["dataset", "--out", "noisy", "--position-m", "0.02", "--rotation-deg", "5", "--seed", "3"],
                    dict(source_root=Path("dataset"), out_root=Path("noisy"), position_m=0.02, rotation_deg=5.0,
                         seed=3)),
    "push": (["dataset", "--repo-id", "me/tavis", "--private", "--branch", "v2"],
             dict(root=Path("dataset"), repo_id="me/tavis", private=True, branch="v2")),
    "push-policy": (["ckpt", "--repo-id", "me/act", "--results", "results.json", "--private", "--branch", "v2",
                     "--out", "card"],
                    dict(checkpoint=Path("ckpt"), repo_id="me/act", results=Path("results.json"), private=True,
                         branch="v2", out=Path("card"))),
    "pull": (["me/tavis", "--root", "here", "--revision", "v2"],
             dict(repo_id="me/tavis", root=Path("here"), revision="v2")),
    "presets": (["diffusion_head_wrist"], dict(name="diffusion_head_wrist")),
    "train": (["diffusion_head_wrist", "--steps=10", "--dataset.root=data"],
              dict(preset="diffusion_head_wrist", lerobot_args=("--steps=10", "--dataset.root=data"))),
    "report": (["evals"], dict(eval_dir=Path("evals"))),
    "curve": (["evals"], dict(eval_root=Path("evals"))),
    "compare": (["a", "b"], dict(eval_a=Path("a"), eval_b=Path("b"))),
    "table-add": (["--robot", "gr1t2", "--task", "peeking_box", "--camera-mode", "fixed_wrist", "--policy", "p",
                   "--training-seed", "7", "--results", "r/results.json", "--baselines", "b.json", "--root", "repo"],
                  dict(robot="gr1t2", task="peeking_box", camera_mode="fixed_wrist", policy="p", training_seed=7,
                       results=Path("r/results.json"), baselines=Path("b.json"), root=Path("repo"))),
    "table": (["--baselines", "b.json", "--root", "repo", "--out", "docs"],
              dict(baselines=Path("b.json"), root=Path("repo"), out_dir=Path("docs"))),
    "ablation": (["--robot", "reachy2", "--baselines", "b.json", "--root", "repo", "--out", "ablation.md"],
                 dict(robot="reachy2", baselines=Path("b.json"), root=Path("repo"), out=Path("ablation.md"))),
}
# The least each subcommand needs, and what the dataclass is then built with directly: the rest are its defaults.
MINIMAL = {
    "demo": ([], {}),
    "gallery": ([], {}),
    "eval": (["--expert", "--out", "evals"], dict(expert=True, out_dir=Path("evals"))),
    "record": (["--out", "raw"], dict(out_dir=Path("raw"))),
    "teleop": (["--task", "peeking_box", "--out", "raw"], dict(task="peeking_box", out_dir=Path("raw"))),
    "view": (["--task", "peeking_box"], dict(task="peeking_box")),
    "convert": (["--from-tavis", "src", "--repo-id", "me/tavis", "--root", "dataset"],
                dict(raw_dir=None, from_tavis=Path("src"), repo_id="me/tavis", root=Path("dataset"))),
    "cache-frames": (["dataset"], dict(root=Path("dataset"))),
    "verify-dataset": (["dataset"], dict(root=Path("dataset"))),
    "noise-state": (["dataset", "--out", "noisy", "--position-m", "0.02", "--rotation-deg", "5"],
                    dict(source_root=Path("dataset"), out_root=Path("noisy"), position_m=0.02, rotation_deg=5.0)),
    "push": (["dataset", "--repo-id", "me/tavis"], dict(root=Path("dataset"), repo_id="me/tavis")),
    "push-policy": (["ckpt", "--repo-id", "me/act"], dict(checkpoint=Path("ckpt"), repo_id="me/act")),
    "pull": (["me/tavis"], dict(repo_id="me/tavis")),
    "presets": ([], {}),
    "train": (["diffusion_head_wrist"], dict(preset="diffusion_head_wrist", lerobot_args=())),
    "report": (["evals"], dict(eval_dir=Path("evals"))),
    "curve": (["evals"], dict(eval_root=Path("evals"))),
    "compare": (["a", "b"], dict(eval_a=Path("a"), eval_b=Path("b"))),
    "table-add": (["--robot", "gr1t2", "--task", "peeking_box", "--camera-mode", "fixed_wrist", "--policy", "p",
                   "--training-seed", "7", "--results", "r/results.json"],
                  dict(robot="gr1t2", task="peeking_box", camera_mode="fixed_wrist", policy="p", training_seed=7,
                       results=Path("r/results.json"))),
    "table": ([], {}),
    "ablation": (["--robot", "gr1t2"], dict(robot="gr1t2")),
}
OFF_THE_COMMAND_LINE = {"record": {"max_attempts_factor"}, "view": {"max_frames"}}


@pytest.fixture(autouse=True)
def offline(monkeypatch):
    """The eval command line names a Hub policy, whose config files `tavis eval` fetches: none is reachable."""
    from huggingface_hub import constants

    monkeypatch.setattr(constants, "HF_HUB_OFFLINE", True)


def _subcommands() -> dict:
    parser = build_parser()
    return next(action for action in parser._actions if isinstance(action, argparse._SubParsersAction)).choices


def _options(argv: list[str]):
    args = build_parser().parse_args(argv)
    return from_args(args.options, args)


def test_every_subcommand_has_a_representative_command_line():
    assert list(_subcommands()) == list(COMMAND_LINES) == list(MINIMAL)


@pytest.mark.parametrize("name", COMMAND_LINES)
def test_a_subcommands_options_are_the_fields_of_its_dataclass(name):
    parser = _subcommands()[name]
    options = parser.load_options()
    generated = {action.dest: (action.option_strings or [action.dest])[0] for action in parser._actions
                 if action.dest != "help"}
    assert generated == {field.name: spelling(options, field.name) for field in command_fields(options)}
    assert {field.name for field in fields(options)} - set(generated) == OFF_THE_COMMAND_LINE.get(name, set())


@pytest.mark.parametrize("name", COMMAND_LINES)
def test_a_command_line_parses_into_the_dataclass(name):
    argv, expected = COMMAND_LINES[name]
    parsed = _options([name, *argv])
    assert {key: getattr(parsed, key) for key in expected} == expected


@pytest.mark.parametrize("name", MINIMAL)
def test_options_left_out_take_the_dataclass_defaults(name):
    argv, given = MINIMAL[name]
    parsed = _options([name, *argv])
    assert parsed == type(parsed)(**given)


def test_every_optional_option_shows_its_default_in_its_help():
    for name, parser in _subcommands().items():
        parser.load_options()
        for action in parser._actions:
            if action.option_strings and not action.required and action.dest != "help":
                assert re.search(r"\bdefault:?\s", action.help or ""), \
                    f"tavis {name} {action.option_strings[0]}: {action.help!r}"


def _help(command: str, flag: str) -> str:
    parser = _subcommands()[command]
    parser.load_options()
    return next(action.help for action in parser._actions if flag in action.option_strings)


def test_a_default_the_help_does_not_state_is_appended():
    assert _help("push", "--private") == "make the Hub repository private (default: off)"
    assert _help("record", "--seed-start") == "first seed (evaluation uses 1000..) (default: 100000)"
    assert _help("record", "--backend").endswith("(default: local)")
    assert _help("eval", "--film-episodes").count("default") == 1  # stated by the help text: not twice
    assert _help("eval", "--seed") == "first episode seed, as lerobot-eval's first (default: 1000)"
    assert _help("convert", "--storage").endswith("(default: av1)")  # "LeRobot's default," states no default


def test_version_names_the_package_and_its_main_dependencies(capsys):
    from importlib.metadata import version

    with pytest.raises(SystemExit) as done:
        build_parser().parse_args(["--version"])
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"tavis (lerobot_env_tavis) {version('lerobot_env_tavis')}; lerobot {version('lerobot')}")


LEAN = """
import json, sys
from lerobot_tavis.cli import build_parser
build_parser().parse_args(sys.argv[1:])
print(json.dumps([m for m in ("mujoco", "torch", "lerobot", "lerobot_tavis.eval.protocol") if m in sys.modules]))
"""


def test_parsing_a_subcommand_imports_only_its_own_module():
    for argv in (["push", "dataset", "--repo-id", "me/tavis"], ["record", "--out", "raw"]):
        out = subprocess.run([sys.executable, "-c", LEAN, *argv], check=True, capture_output=True, text=True)
        assert json.loads(out.stdout) == []
