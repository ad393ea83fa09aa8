"""What produced an evaluation: the run identity `tavis eval` stores with every cell and every episode record.

The identity is a JSON object of the settings that decide a cell's episodes: the policy (a local checkpoint's path
and the SHA-256 of its files, a Hub repo id by name, or the scripted demonstrators), its `--policy-option` fields,
robot, camera mode, image size ([H, W] px), episode length (s), first seed, episodes per task and the package
version. `code_commit`, the git commit of the code when it runs from a git checkout, is recorded but not compared:
most commits do not change what an evaluation plays. A local checkpoint counts as the same policy when its files
are, wherever it lies. `tavis eval` keeps the identity in `.<cell>.chunks/run.json` while it plays a
cell, then in the cell's `eval_info.json` and in every record of its `episodes.jsonl` (both under "run"), so a
resumed or re-run evaluation with other settings is refused and `tavis report` finds a cell that mixes runs.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
from importlib import metadata
from pathlib import Path

from lerobot_tavis.dataset_tools.raw import file_sha256
from lerobot_tavis.errors import InputError

RUN_FIELD = "run"  # the key of the identity in eval_info.json and in each episode record
RUN_FILE = "run.json"  # the identity of a cell being played, in its chunk folder
DEMONSTRATORS = "scripted demonstrators"
# Compared fields, each with the `tavis eval` option that sets it.
OPTIONS = {"policy": "--policy", "policy_sha256": "--policy", "policy_options": "--policy-option",
           "robot": "--robot", "camera_mode": "--camera-mode", "image_size": "--image-size",
           "episode_length_s": "--episode-length-s", "seed": "--seed", "episodes": "--episodes",
           "code_version": "lerobot_env_tavis"}


def run_identity(cfg) -> dict:
    """The identity of the `tavis eval` run `cfg` (a ProtocolConfig), as JSON values."""
    local = cfg.policy_path is not None and Path(cfg.policy_path).is_dir()
    policy = (DEMONSTRATORS if cfg.policy_path is None
              else str(Path(cfg.policy_path).absolute()) if local else str(cfg.policy_path))
    identity = {"policy": policy, "policy_sha256": checkpoint_sha256(cfg.policy_path) if local else None,
                "policy_options": [list(pair) for pair in cfg.policy_options], "robot": cfg.robot,
                "camera_mode": cfg.camera_mode, "image_size": list(cfg.image_size),
                "episode_length_s": float(cfg.episode_length_s), "seed": cfg.seed, "episodes": cfg.n_episodes,
                "code_version": code_version(), "code_commit": code_commit()}
    return json.loads(json.dumps(identity))  # as it reads back from a file


def read_identity(path: Path) -> dict:
    """A stored identity (`run.json`); InputError naming the file when it is not a JSON object."""
    try:
        identity = json.loads(Path(path).read_text())
    except (json.JSONDecodeError, UnicodeDecodeError):
        identity = None
    if not isinstance(identity, dict):
        raise InputError(f"{path}: not a run identity (a JSON object)")
    return identity


def checkpoint_sha256(directory: str | Path) -> str:
    """SHA-256 over every file of a checkpoint directory: each file's path (relative, POSIX) and content digest."""
    directory = Path(directory)
    digest = hashlib.sha256()
    for path in sorted(p for p in directory.rglob("*") if p.is_file()):
        digest.update(f"{path.relative_to(directory).as_posix()}\0{file_sha256(path)}\n".encode())
    return digest.hexdigest()


def code_version() -> str | None:
    """The installed version of the distribution (None when the code runs uninstalled)."""
    try:
        return metadata.version("lerobot_env_tavis")
    except metadata.PackageNotFoundError:
        return None


def code_commit() -> str | None:
    """The git commit of this package's code, when it runs from a git checkout that tracks it (else None: an
    installed copy, even one inside some other checkout)."""
    package = str(Path(__file__).parents[1])
    try:
        tracked = subprocess.run(["git", "-C", package, "ls-files", "--error-unmatch", "__init__.py"],
                                 capture_output=True, timeout=10)
        head = subprocess.run(["git", "-C", package, "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return head.stdout.strip() if tracked.returncode == 0 and head.returncode == 0 else None


# The fields that decide how an episode of a given seed plays: two runs that differ only in their seeds or episode
# counts play the same episodes, and a report may pool them.
EPISODE_FIELDS = tuple(name for name in OPTIONS if name not in ("seed", "episodes"))


def differences(stored: dict, wanted: dict, fields: tuple[str, ...] = tuple(OPTIONS)) -> list[str]:
    """The `fields` in which two identities differ, in OPTIONS order. The checkpoint's path counts only when either
    identity lacks its hash."""
    hashed = bool(stored.get("policy_sha256") and wanted.get("policy_sha256"))
    return [name for name in fields
            if stored.get(name) != wanted.get(name) and not (name == "policy" and hashed)]


def setting_text(name: str, identity: dict) -> str:
    """How field `name` of `identity` reads on the command line, e.g. `--robot gr1t2`, `--expert`."""
    value = identity.get(name)
    if name == "policy":
        return "--expert" if value == DEMONSTRATORS else f"--policy {value}"
    if name == "policy_sha256":
        return f"--policy {identity.get('policy')} (files sha256 {str(value)[:12]})"
    if name == "policy_options":
        return " ".join(f"--policy-option {field}={json.dumps(v)}" for field, v in value) or "no --policy-option"
    if name == "image_size":
        return f"--image-size {value[0]}x{value[1]}"
    if name == "episode_length_s":
        return f"--episode-length-s {value:g}"
    if name == "code_version":
        return f"lerobot_env_tavis {value}"
    return f"{OPTIONS[name]} {value}"


def difference_text(stored: dict, wanted: dict) -> str:
    """The first difference between a stored and a wanted identity, and how many more, in one phrase."""
    names = differences(stored, wanted)
    text = f"{setting_text(names[0], stored)}, not {setting_text(names[0], wanted)}"
    more = [option for option in dict.fromkeys(OPTIONS[name] for name in names[1:]) if option != OPTIONS[names[0]]]
    return text + (f" (and {', '.join(more)} differ too)" if more else "")
