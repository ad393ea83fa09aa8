"""Share TAVIS datasets on the Hugging Face Hub: the dataset card, push and pull.

A push uploads the local LeRobotDataset v3.0 with LeRobot's `push_to_hub`, replaces LeRobot's generic card by
ours (README.md) and then tags the result with the codebase version (`v3.0`), which LeRobot's loader needs.
Hub failures become a one-line `HubError`: not logged in, Hub unreachable, repository not found.
LeRobot and huggingface_hub are imported inside the functions: importing this module stays light.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote

from lerobot_tavis import checks
from lerobot_tavis.dataset_tools.features import JOINT_POS_KEY, SPLIT_KEY, STATE_KEY, TASK_NAME_KEY
from lerobot_tavis.dataset_tools.frames import check_files
from lerobot_tavis.envs.tasks.catalog import TASKS, task_sort_key
from lerobot_tavis.errors import InputError, PathNotFoundError, TavisError

LICENSE = "cc-by-4.0"
TAGS = ("lerobot", "tavis", "robotics")
SUITE_TITLES = {"tavis_head": "TAVIS-Head", "tavis_hands": "TAVIS-Hands"}
REFERENCE_URL = "https://github.com/spiglerg/tavis"
CITATION = r"""@misc{tavis,
  title = {TAVIS: a benchmark for egocentric active vision and anticipatory gaze},
  howpublished = {\url{https://github.com/spiglerg/tavis}},
  note = {reference implementation, version 1.0.0}
}"""
FEATURE_CONTENT = {
    STATE_KEY: "measured canonical state, same layout as `action`",
    JOINT_POS_KEY: "the robot's joint positions",
    "action": "canonical action taken from this frame's observation",
    TASK_NAME_KEY: "TAVIS task of the episode",
    SPLIT_KEY: "TAVIS split of the episode (`id`, `ood_spatial`, `ood_init_pose`)",
    "timestamp": "seconds since the episode start",
    "frame_index": "frame number within the episode",
    "episode_index": "episode number",
    "index": "frame number within the dataset",
    "task_index": "row of LeRobot's `task` (the prompt) in meta/tasks.parquet",
}
PROVENANCE = "The data was produced by `lerobot_tavis`, the MuJoCo port of TAVIS, with its scripted demonstrators."
NOT_LOGGED_IN = "not logged in to the Hugging Face Hub: run `hf auth login` or set HF_TOKEN"


class HubError(TavisError, RuntimeError):
    """A Hugging Face Hub operation failed: not logged in, Hub unreachable, or repository not found."""


def dataset_card(dataset, *, provenance: str = PROVENANCE) -> str:
    """The dataset card (README.md, Markdown with YAML front matter) of a TAVIS `LeRobotDataset`.

    `provenance`: the sentence saying where the data comes from (say so for data imported from the reference).
    """
    from huggingface_hub import DatasetCardData

    meta = dataset.meta
    missing = [key for key in (TASK_NAME_KEY, SPLIT_KEY) if key not in meta.features]
    if missing:
        raise InputError(f"{dataset.root} is not a TAVIS dataset: it lacks the features {missing}")
    front_matter = DatasetCardData(
        license=LICENSE, tags=["LeRobot", *TAGS], task_categories=["robotics"],
        configs=[{"config_name": "default", "data_files": "data/*/*.parquet"}],
    ).to_yaml()
    cameras = []
    for key in meta.camera_keys:
        height, width = meta.features[key]["shape"][:2]
        codec = meta.features[key].get("info", {}).get("video.codec")
        encoding = f" ({codec} video)" if codec else ""
        cameras.append(f"`{key.removeprefix('observation.images.')}` {width}×{height}{encoding}")
    summary = [
        ("Robot", f"`{meta.robot_type}`" if meta.robot_type else "not recorded"),
        ("Episodes", meta.total_episodes),
        ("Frames", meta.total_frames),
        ("Frame rate", f"{meta.fps} fps"),
        ("Cameras", ", ".join(cameras) or "none"),
        ("Prompts", f"{len(meta.tasks)} distinct (LeRobot's `task`)"),
        ("License", "CC-BY-4.0"),
    ]
    features = [
        f"| `{key}` | {spec['dtype']} | {'×'.join(str(n) for n in spec['shape'])} | "
        f"{_feature_content(key)} |"
        for key, spec in meta.features.items()
    ]
    lines = [
        "---", front_matter.rstrip("\n"), "---", "",
        f"# TAVIS dataset `{dataset.repo_id}`", "",
        f"Demonstrations for [TAVIS]({REFERENCE_URL}), a benchmark for egocentric active vision and anticipatory "
        f"gaze. Format: LeRobotDataset {meta.info.codebase_version} ([LeRobot](https://github.com/huggingface/lerobot)).",
        "", "## Summary", "", "| | |", "|---|---|", *(f"| {name} | {value} |" for name, value in summary),
        "", "## Tasks", "", "| Task | Suite | Episodes | Frames | Splits (episodes) |", "|---|---|---:|---:|---|",
        *_task_rows(Path(dataset.root)),
        "", "## Features", "", "| Key | Type | Shape | Content |", "|---|---|---|---|", *features,
        "", "## Loading", "", "```python", "from lerobot.datasets import LeRobotDataset", "",
        f'dataset = LeRobotDataset("{dataset.repo_id}")', "```",
        "", "## License", "",
        "The data is released under the Creative Commons Attribution 4.0 International license (CC-BY-4.0, "
        "https://creativecommons.org/licenses/by/4.0/).",
        "", "## Citation", "",
        f"{provenance} Please cite the TAVIS software:", "", "```bibtex", CITATION, "```", "",
    ]
    return "\n".join(lines)


def push_dataset(root: str | Path, repo_id: str, *, private: bool = False, branch: str | None = None,
                 provenance: str = PROVENANCE) -> str:
    """Upload the local TAVIS dataset at `root` to the Hub as `repo_id` with our card; returns the dataset's URL.

    Checks `repo_id`, that `root` is a dataset and that a Hub token exists before uploading anything.
    """
    checks.repo_id(repo_id)
    root = _check_dataset_root(root)
    from huggingface_hub import HfApi, constants, get_token
    from huggingface_hub.errors import RevisionNotFoundError
    from lerobot.datasets import CODEBASE_VERSION, LeRobotDataset

    if get_token() is None:
        raise HubError(NOT_LOGGED_IN)
    dataset = LeRobotDataset(repo_id, root=root, video_backend="pyav")  # nothing is decoded here
    card = dataset_card(dataset, provenance=provenance)
    with hub_errors(repo_id):
        dataset.push_to_hub(branch=branch, tags=list(TAGS), license=LICENSE, tag_version=False, private=private)
        api = HfApi()
        api.upload_file(path_or_fileobj=card.encode(), path_in_repo="README.md", repo_id=repo_id,
                        repo_type="dataset", revision=branch, commit_message="TAVIS dataset card")
        with contextlib.suppress(RevisionNotFoundError):
            api.delete_tag(repo_id, tag=CODEBASE_VERSION, repo_type="dataset")
        api.create_tag(repo_id, tag=CODEBASE_VERSION, revision=branch, repo_type="dataset")
    url = f"{constants.ENDPOINT}/datasets/{repo_id}"
    return f"{url}/tree/{quote(branch, safe='')}" if branch else url


def pull_dataset(repo_id: str, root: str | Path | None = None, revision: str | None = None):
    """The `LeRobotDataset` `repo_id` from the Hub, downloaded into `root` (default: LeRobot's Hub cache).

    A complete copy already in `root` is loaded without contacting the Hub. The metadata and data files already
    there are read first: a damaged one (e.g. a download cut short) is an InputError naming it.
    """
    checks.repo_id(repo_id)
    from lerobot.datasets import LeRobotDataset
    from lerobot.utils.constants import HF_LEROBOT_HOME

    from lerobot_tavis.dataset_tools.quiet import video_backend

    local = Path(root) if root is not None else HF_LEROBOT_HOME / repo_id
    try:
        check_files(local)
    except InputError as error:
        raise InputError(f"{error}; remove it to download it again") from None
    with hub_errors(repo_id):
        return LeRobotDataset(repo_id, root=root, revision=revision, video_backend=video_backend())


def _check_dataset_root(root: str | Path) -> Path:
    root = Path(root)
    if not (root / "meta" / "info.json").is_file() or not any(root.glob("data/*/*.parquet")):
        raise PathNotFoundError(f"{root} is not a LeRobotDataset: it needs meta/info.json and data/*/*.parquet "
                                "(a dataset written and finalize()d by LeRobot)")
    check_files(root)
    return root


def _task_rows(root: Path) -> list[str]:
    """Markdown rows: episodes and frames per task, in catalog order, read from the per-frame `task_name`."""
    import pandas as pd

    columns = ["episode_index", TASK_NAME_KEY, SPLIT_KEY]
    frames = pd.concat([pd.read_parquet(path, columns=columns) for path in sorted(root.glob("data/*/*.parquet"))])
    episodes = frames.groupby("episode_index").agg(task=(TASK_NAME_KEY, "first"), split=(SPLIT_KEY, "first"),
                                                   frames=(TASK_NAME_KEY, "size"))
    rows = []
    for task in sorted(episodes["task"].unique(), key=task_sort_key):
        of_task = episodes[episodes["task"] == task]
        suite = SUITE_TITLES.get(TASKS[task].suite, TASKS[task].suite) if task in TASKS else "unknown"
        splits = ", ".join(f"{split}: {count}" for split, count in of_task["split"].value_counts(sort=False).items())
        rows.append(f"| `{task}` | {suite} | {len(of_task)} | {of_task['frames'].sum()} | {splits} |")
    return rows


def _feature_content(key: str) -> str:
    if key.startswith("observation.images."):
        return f"RGB image of the `{key.removeprefix('observation.images.')}` camera (height × width × channels)"
    return FEATURE_CONTENT.get(key, "")


@contextlib.contextmanager
def hub_errors(repo_id: str, kind: str = "dataset") -> Iterator[None]:
    """Turn the Hub's authentication, network and not-found exceptions into a one-line `HubError`; `kind` names
    what `repo_id` holds (dataset, model)."""
    import httpx
    from huggingface_hub import constants
    from huggingface_hub.errors import (GatedRepoError, HfHubHTTPError, LocalEntryNotFoundError, OfflineModeIsEnabled,
                                        RepositoryNotFoundError, RevisionNotFoundError)

    endpoint = constants.ENDPOINT
    try:
        yield
    except OfflineModeIsEnabled as exc:
        raise HubError(f"cannot reach the Hugging Face Hub at {endpoint}: offline mode is on; "
                       "unset HF_HUB_OFFLINE to go online") from exc
    except GatedRepoError as exc:
        raise HubError(f"{repo_id} is gated on the Hugging Face Hub: request access on its page, then log in "
                       "(`hf auth login` or HF_TOKEN)") from exc
    except RepositoryNotFoundError as exc:
        raise HubError(f"{kind} {repo_id} was not found on the Hugging Face Hub at {endpoint} (a private one "
                       "needs `hf auth login` or HF_TOKEN)") from exc
    except RevisionNotFoundError as exc:
        detail = str(exc).splitlines()[0] if str(exc) else "revision not found"
        raise HubError(f"{kind} {repo_id} on the Hugging Face Hub at {endpoint}: {detail}") from exc
    except HfHubHTTPError as exc:
        status = exc.response.status_code
        if status == 401:
            raise HubError(f"{NOT_LOGGED_IN} (the Hub rejected the token, HTTP 401)") from exc
        if status == 403:
            raise HubError(f"the Hugging Face Hub refused access to {repo_id} (HTTP 403): the token may lack write "
                           "access; run `hf auth login` with a write token or set HF_TOKEN") from exc
        raise
    except (httpx.TransportError, ConnectionError, TimeoutError, LocalEntryNotFoundError) as exc:
        raise HubError(f"cannot reach the Hugging Face Hub at {endpoint} ({type(exc).__name__}): check the network "
                       "connection, the HF_ENDPOINT and proxy settings, and that HF_HUB_OFFLINE is not set") from exc
