"""Share a trained policy on the Hugging Face Hub: its model card and the push of its checkpoint.

`push_policy` uploads a checkpoint's `pretrained_model` folder (weights, configs, processors) as a model repository
in one commit, with a model card (README.md) written from what the folder records: the env, robot, task, camera
mode and image size of its training config (`train_config.json`), the dataset, the preset whose policy type and
camera mode it matches, the commands that evaluate it and train it again, and, given a `tavis report`
`results.json`, its success rates with their Wilson 95% intervals. `lerobot-eval --policy.path=<repo id>
--env.type=tavis` then evaluates it with the env settings it was trained with (`envs.checkpoint_settings`).
Hub failures are the one-line `HubError`s of `dataset_tools.hub`; huggingface_hub is imported inside the functions.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path
from urllib.parse import quote

from lerobot_tavis import checks
from lerobot_tavis.dataset_tools.hub import CITATION, NOT_LOGGED_IN, REFERENCE_URL, HubError, hub_errors
from lerobot_tavis.envs.checkpoint_settings import (POLICY_CONFIG_NAME, TRAIN_CONFIG_NAME, pretrained_model_dir,
                                                    settings_from_configs)
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, SUITES
from lerobot_tavis.errors import InputError, PathNotFoundError
from lerobot_tavis.policy_configs import presets

TAGS = ("lerobot", "tavis", "robotics")
WEIGHTS_NAME = "model.safetensors"
RESULTS_NAME = "results.json"
EVAL_EPISODES = 96  # the protocol's episodes per task and split


def policy_card(checkpoint: str | Path, repo_id: str, results: dict | None = None) -> str:
    """The model card (README.md, Markdown with YAML front matter) of the checkpoint folder `checkpoint` published
    as `repo_id`; `results`: a `tavis report` results.json, parsed."""
    from huggingface_hub import ModelCardData

    folder = Path(checkpoint)
    policy = json.loads((folder / POLICY_CONFIG_NAME).read_text())
    train_path = folder / TRAIN_CONFIG_NAME
    train = json.loads(train_path.read_text()) if train_path.is_file() else {}
    settings = settings_from_configs(policy, train)
    env = train.get("env") or {}
    env = env if env.get("type") == "tavis" else {}
    dataset = train.get("dataset") or {}
    policy_type = policy.get("type", "unknown")
    task = env.get("task", "not recorded")
    size = "x".join(map(str, settings.image_size)) if settings.image_size else None
    matching = [name for name, (kind, mode, _) in presets().items()
                if kind == policy_type and mode == settings.camera_mode]
    data_id = dataset.get("repo_id")
    front_matter = ModelCardData(
        library_name="lerobot", pipeline_tag="robotics", tags=[*TAGS, policy_type],
        datasets=[data_id] if data_id and not data_id.startswith("local/") else None).to_yaml()
    recipe = [f"{name} {train[key]}" for name, key in (("steps", "steps"), ("batch size", "batch_size"),
                                                         ("seed", "seed")) if train.get(key) is not None]
    summary = [
        ("Policy", f"LeRobot `{policy_type}`"),
        ("Env", "`--env.type=tavis` (the LeRobot env plugin `lerobot_env_tavis`: TAVIS in MuJoCo)"),
        ("Task", f"`{task}`"),
        ("Robot", f"`{settings.robot}`" if settings.robot else "not recorded"),
        ("Camera mode", f"`{settings.camera_mode}`" if settings.camera_mode else "not recorded"),
        ("Cameras read", ", ".join(f"`{camera}`" for camera in settings.cameras or ()) or "none"),
        ("Image size", f"{size} (height x width)" if size else "not recorded"),
        ("Training data", _training_data(data_id)),
        ("Recipe", (f"preset `{matching[0]}`" if len(matching) == 1 else "no preset of this package")
         + (f"; {', '.join(recipe)}" if recipe else "")),
    ]
    name = repo_id.split("/")[-1]
    env_flags = [f"--env.task={task}"] if env.get("task") else []
    protocol_flags = [f"--tasks {task}"] if task in BENCHMARK_TASKS else [f"--suite {task}"] if task in SUITES else []
    evaluate = [" ".join(["lerobot-eval", f"--policy.path={repo_id}", "--env.type=tavis", *env_flags,
                          f"--eval.n_episodes={EVAL_EPISODES}", f"--output_dir=outputs/eval/{name}"]),
                " ".join(["tavis eval", f"--policy {repo_id}", *protocol_flags, f"--out outputs/protocol/{name}"])]
    lines = [
        "---", front_matter.rstrip("\n"), "---", "",
        f"# TAVIS policy `{repo_id}`", "",
        f"A LeRobot `{policy_type}` policy for [TAVIS]({REFERENCE_URL}), a benchmark for egocentric active vision and "
        "anticipatory gaze, trained and evaluated in its MuJoCo port (`lerobot_tavis`).",
        "", "## Summary", "", "| | |", "|---|---|", *(f"| {name} | {value} |" for name, value in summary),
        "", "## Evaluate", "",
        "With the `lerobot_env_tavis` package installed (it registers `--env.type=tavis` and `tavis`); the env "
        "renders the robot, camera mode and image size this checkpoint was trained with unless told otherwise. "
        "`tavis eval` plays the benchmark's protocol (splits id, ood_spatial, ood_init_pose; 96 episodes each) and "
        "writes the report.", "", "```bash", *evaluate, "```",
    ]
    if len(matching) == 1 and data_id:
        command = [f"lerobot-train --config_path=$(tavis presets {matching[0]}) --dataset.repo_id={data_id}",
                   *env_flags, *(f"--{key}={train[key]}" for key in ("steps", "batch_size", "seed")
                                 if train.get(key) is not None)]
        lines += ["", "## Train again", "", "```bash", " ".join(command), "```"]
    if results is not None:
        lines += ["", "## Results", "", *_results_lines(results)]
    lines += ["", "## Citation", "", "Please cite the TAVIS software:", "", "```bibtex", CITATION, "```", ""]
    return "\n".join(lines)


def push_policy(checkpoint: str | Path, repo_id: str, *, results: str | Path | None = None, private: bool = False,
                branch: str | None = None, out: str | Path | None = None) -> str:
    """Upload the checkpoint folder `checkpoint` (a `pretrained_model`) to the Hub as the model `repo_id`, with our
    card and, when given, the `results` file (a `tavis report` results.json); returns the model's URL. With `out`,
    write that folder to `out` instead (complete or not at all, replacing an older one) and return its path: no
    network and no login, ready for `huggingface-cli upload <repo id> <out>`.

    Checks `repo_id`, the folder, the results file and (for an upload) that a Hub token exists before writing or
    uploading anything."""
    checks.repo_id(repo_id)
    folder = pretrained_model_dir(checkpoint)
    if not (folder / WEIGHTS_NAME).is_file():
        raise PathNotFoundError(f"{folder} holds no {WEIGHTS_NAME}: pass a checkpoint's pretrained_model folder")
    report = _read_results(Path(results)) if results is not None else None
    if out is not None:
        from lerobot_tavis.staging import staged_directory

        with staged_directory(out, overwrite=True) as staged:
            _stage(folder, policy_card(folder, repo_id, report), results, staged)
        return str(out)
    from huggingface_hub import HfApi, constants, get_token

    if get_token() is None:
        raise HubError(NOT_LOGGED_IN)
    card = policy_card(folder, repo_id, report)
    with tempfile.TemporaryDirectory(prefix="tavis-policy-") as scratch:
        staged = Path(scratch) / "policy"
        _stage(folder, card, results, staged)
        with hub_errors(repo_id, "model"):
            api = HfApi()
            api.create_repo(repo_id, repo_type="model", private=private, exist_ok=True)
            if branch:
                api.create_branch(repo_id, branch=branch, repo_type="model", exist_ok=True)
            api.upload_folder(folder_path=staged, repo_id=repo_id, repo_type="model", revision=branch,
                              commit_message="TAVIS policy checkpoint and model card")
    url = f"{constants.ENDPOINT}/{repo_id}"
    return f"{url}/tree/{quote(branch, safe='')}" if branch else url


def _stage(folder: Path, card: str, results: str | Path | None, staged: Path) -> None:
    """The model repository's content at `staged` (made here): the checkpoint folder, README.md and results.json."""
    shutil.copytree(folder, staged)
    (staged / "README.md").write_text(card)
    if results is not None:
        shutil.copyfile(results, staged / RESULTS_NAME)


def _read_results(path: Path) -> dict:
    """A `tavis report` results.json; InputError naming the file when it is not one."""
    if not path.is_file():
        raise PathNotFoundError(f"{path}: no such results file (a `tavis report` or `tavis eval` results.json)")
    try:
        report = json.loads(path.read_text())
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: not a JSON file ({error.msg})") from None
    if not (isinstance(report, dict) and isinstance(report.get("cells"), list)):
        raise InputError(f"{path}: not a `tavis report` results.json (it needs a list of cells)")
    return report


def _results_lines(results: dict) -> list[str]:
    """Markdown: one row per cell (task, split) of a results.json, and where its episodes were played."""
    rows = []
    for cell in results["cells"]:
        galt = cell.get("galt_median_s")
        rows.append(f"| `{cell['task']}` | {cell['split']} | {cell['n']} | {100 * cell['success_rate']:.1f}% | "
                    f"[{100 * cell['ci_low']:.1f}, {100 * cell['ci_high']:.1f}] | "
                    f"{'-' if galt is None else f'{galt:.2f}'} |")
    sources = results.get("sources") or []
    robots = sorted({robot for source in sources for robot in source.get("robots", ())})
    modes = sorted({mode for source in sources for mode in source.get("camera_modes", ())})
    played = f" on {', '.join(robots)} with camera mode {', '.join(modes)}" if robots and modes else ""
    return [f"Success rate per task and split{played} (`tavis report`; 95% Wilson intervals; GALT: median gaze-action "
            "lead time of the successful episodes, seconds). The file is `results.json` in this repository.", "",
            "| Task | Split | Episodes | Success | 95% CI | GALT (s) |", "|---|---|---:|---:|---|---:|", *rows]


def _training_data(repo_id: str | None) -> str:
    if not repo_id:
        return "not recorded"
    if repo_id.startswith("local/"):
        return f"`{repo_id}`, a local dataset (not on the Hub)"
    return f"[`{repo_id}`](https://huggingface.co/datasets/{repo_id})"
