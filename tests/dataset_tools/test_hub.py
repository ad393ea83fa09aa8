"""Dataset card, push and pull. No test reaches the network: the Hub endpoint is a closed local port, and the
successful push runs against fakes of the huggingface_hub calls that upload."""

from pathlib import Path

import httpx
import numpy as np
import pytest

from lerobot_tavis.dataset_tools.features import dataset_features
from lerobot_tavis.dataset_tools.hub import HubError, dataset_card, pull_dataset, push_dataset
from tests.conftest import free_port

REPO_ID = "someone/tavis_toy"
EPISODES = (("conditional_pick", "id", "Look at the card."), ("wait_then_act", "id", "Watch the light."),
            ("wait_then_act", "ood_spatial", "Watch the light."))
UPLOADING = ("create_repo", "create_branch", "upload_folder", "upload_large_folder", "upload_file", "delete_tag",
             "create_tag")


@pytest.fixture(scope="module")
def dataset_root(tmp_path_factory):
    """A finished 3-episode, 5-frame TAVIS dataset (one 48x64 head camera, 2 joints) on disk."""
    from lerobot.datasets import LeRobotDataset

    root = tmp_path_factory.mktemp("hub") / "tavis_toy"
    dataset = LeRobotDataset.create("local/tavis_toy", fps=20, root=root, robot_type="gr1t2", video_backend="pyav",
                                    features=dataset_features(["joint_a", "joint_b"], ["head"], (48, 64)))
    for task_name, split, prompt in EPISODES:
        for _ in range(5):
            dataset.add_frame({"observation.images.head": np.zeros((48, 64, 3), np.uint8),
                               "observation.state": np.zeros(19, np.float32),
                               "observation.joint_pos": np.zeros(2, np.float32),
                               "action": np.zeros(19, np.float32),
                               "task_name": task_name, "split": split, "task": prompt})
        dataset.save_episode()
    dataset.finalize()
    return root


def load(root, repo_id=REPO_ID):
    from lerobot.datasets import LeRobotDataset

    return LeRobotDataset(repo_id, root=root, video_backend="pyav")


@pytest.fixture
def hub(monkeypatch, tmp_path):
    """An isolated Hub: no token anywhere, online mode, endpoint = a closed local port."""
    from huggingface_hub import constants

    for name in ("HF_TOKEN", "HUGGING_FACE_HUB_TOKEN", "HF_OIDC_RESOURCE"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(constants, "HF_TOKEN_PATH", str(tmp_path / "no_token"))
    monkeypatch.setattr(constants, "HF_HUB_OFFLINE", False)
    endpoint = f"http://127.0.0.1:{free_port()}"  # nothing listens there: connecting is refused at once
    monkeypatch.setattr(constants, "ENDPOINT", endpoint)
    return endpoint


@pytest.fixture
def uploads(monkeypatch):
    """Replace every huggingface_hub call that writes to the Hub by a recorder; yields the (name, kwargs) list."""
    from huggingface_hub import HfApi
    from huggingface_hub.repocard import RepoCard

    calls = []

    def recorder(name):
        def record(self, *args, **kwargs):
            calls.append((name, {"args": args, **kwargs}))
        return record

    for name in UPLOADING:
        monkeypatch.setattr(HfApi, name, recorder(name))
    monkeypatch.setattr(RepoCard, "push_to_hub", recorder("card.push_to_hub"))
    return calls


def http_error(cls, status: int):
    request = httpx.Request("GET", "http://127.0.0.1/api/datasets/x")
    return cls(f"{status} error", response=httpx.Response(status, request=request))


def test_card_lists_tasks_robot_cameras_license_and_citation(dataset_root):
    card = dataset_card(load(dataset_root))
    front_matter = card.split("---\n")[1]
    assert card.startswith("---\n")
    assert "license: cc-by-4.0" in front_matter and "- robotics" in front_matter
    assert all(f"- {tag}\n" in front_matter for tag in ("lerobot", "tavis", "robotics"))
    assert "| `conditional_pick` | TAVIS-Head | 1 | 5 | id: 1 |" in card
    assert "| `wait_then_act` | TAVIS-Head | 2 | 10 | id: 1, ood_spatial: 1 |" in card
    for text in ("| Robot | `gr1t2` |", "| Episodes | 3 |", "| Frames | 15 |", "| Frame rate | 20 fps |",
                 "`head` 64×48", "| `observation.joint_pos` | float32 | 2 |", "| `task_name` | string |", "CC-BY-4.0",
                 "@misc{tavis,", r"howpublished = {\url{https://github.com/spiglerg/tavis}}",
                 "note = {reference implementation, version 1.0.0}", "MuJoCo port", "scripted demonstrators",
                 f'LeRobotDataset("{REPO_ID}")'):
        assert text in card, text
    assert "author" not in card.lower()


def test_card_provenance_can_be_stated(dataset_root):
    card = dataset_card(load(dataset_root), provenance="Imported from the reference's teleoperated data.")
    assert "Imported from the reference's teleoperated data." in card and "scripted" not in card


def test_push_without_token_fails_before_uploading(dataset_root, hub, uploads):
    with pytest.raises(HubError, match=r"not logged in .*`hf auth login` or set HF_TOKEN"):
        push_dataset(dataset_root, REPO_ID)
    assert uploads == []


def test_push_root_that_is_not_a_dataset(tmp_path, hub, uploads, monkeypatch):
    monkeypatch.setenv("HF_TOKEN", "hf_test")
    (tmp_path / "empty").mkdir()
    for root in (tmp_path / "missing", tmp_path / "empty"):
        with pytest.raises(FileNotFoundError, match="is not a LeRobotDataset.*meta/info.json"):
            push_dataset(root, REPO_ID)
    assert uploads == []


def test_push_with_unreachable_hub(dataset_root, hub, monkeypatch):
    monkeypatch.setenv("HF_TOKEN", "hf_test")
    with pytest.raises(HubError, match=rf"cannot reach the Hugging Face Hub at {hub} .*network connection"):
        push_dataset(dataset_root, REPO_ID)


def test_push_in_offline_mode(dataset_root, hub, monkeypatch):
    from huggingface_hub import constants

    monkeypatch.setenv("HF_TOKEN", "hf_test")
    monkeypatch.setattr(constants, "HF_HUB_OFFLINE", True)
    with pytest.raises(HubError, match="offline mode is on; unset HF_HUB_OFFLINE"):
        push_dataset(dataset_root, REPO_ID)


@pytest.mark.parametrize("status, message", [(401, "not logged in"), (403, "refused access to someone/tavis_toy")])
def test_push_with_rejected_token(dataset_root, hub, uploads, monkeypatch, status, message):
    from huggingface_hub import HfApi
    from huggingface_hub.errors import HfHubHTTPError

    def refuse(self, *args, **kwargs):
        raise http_error(HfHubHTTPError, status)

    monkeypatch.setenv("HF_TOKEN", "hf_test")
    monkeypatch.setattr(HfApi, "create_repo", refuse)
    with pytest.raises(HubError, match=message) as error:
        push_dataset(dataset_root, REPO_ID)
    assert "hf auth login" in str(error.value) and "\n" not in str(error.value)
    assert uploads == []


def test_push_uploads_the_folder_then_our_card_then_tags(dataset_root, hub, uploads, monkeypatch):
    monkeypatch.setenv("HF_TOKEN", "hf_test")
    url = push_dataset(dataset_root, REPO_ID, private=True)
    assert url == f"{hub}/datasets/{REPO_ID}"
    names = [name for name, _ in uploads]
    assert names == ["create_repo", "upload_folder", "card.push_to_hub", "upload_file", "delete_tag", "create_tag"]
    calls = dict(uploads)
    assert calls["create_repo"]["repo_id"] == REPO_ID and calls["create_repo"]["private"] is True
    assert calls["upload_folder"]["folder_path"] == dataset_root and "images/" in calls["upload_folder"][
        "ignore_patterns"]
    readme = calls["upload_file"]
    assert readme["path_in_repo"] == "README.md" and readme["repo_type"] == "dataset" and readme["revision"] is None
    assert readme["path_or_fileobj"].decode() == dataset_card(load(dataset_root))
    assert calls["create_tag"]["tag"] == "v3.0" and calls["create_tag"]["revision"] is None


def test_push_to_a_branch(dataset_root, hub, uploads, monkeypatch):
    monkeypatch.setenv("HF_TOKEN", "hf_test")
    assert push_dataset(dataset_root, REPO_ID, branch="ep/3") == f"{hub}/datasets/{REPO_ID}/tree/ep%2F3"
    calls = dict(uploads)
    assert calls["create_branch"]["branch"] == "ep/3"
    assert calls["upload_folder"]["revision"] == calls["upload_file"]["revision"] == "ep/3"
    assert calls["create_tag"]["revision"] == "ep/3"


def test_pull_with_unreachable_hub(hub, tmp_path):
    with pytest.raises(HubError, match=rf"cannot reach the Hugging Face Hub at {hub}"):
        pull_dataset(REPO_ID, root=tmp_path / "pulled")


def test_pull_of_a_missing_repo(hub, tmp_path, monkeypatch):
    from huggingface_hub import HfApi
    from huggingface_hub.errors import RepositoryNotFoundError

    def missing(self, *args, **kwargs):
        raise http_error(RepositoryNotFoundError, 404)

    monkeypatch.setattr(HfApi, "list_repo_refs", missing)
    with pytest.raises(HubError, match=f"dataset {REPO_ID} was not found on the Hugging Face Hub"):
        pull_dataset(REPO_ID, root=tmp_path / "pulled")


def test_pull_of_a_local_copy_needs_no_hub(dataset_root, hub):
    dataset = pull_dataset(REPO_ID, root=dataset_root)
    assert dataset.meta.total_episodes == 3 and dataset.repo_id == REPO_ID


# A policy checkpoint: `tavis push-policy`. The checkpoint is its files as lerobot-train writes them (the weights
# file's content is not read).
POLICY_REPO = "someone/act_conditional_pick"
TRAIN_CONFIG = {"dataset": {"repo_id": "someone/tavis-head-gr1t2", "root": "/data/tavis"}, "steps": 3200,
                "batch_size": 128, "seed": 1000,
                "env": {"type": "tavis", "task": "conditional_pick", "robot": "gr1t2", "camera_mode": "head_wrist",
                        "image_size": [120, 160]},
                "policy": {"type": "act_hand_relative"}}
RESULTS = {"cells": [{"task": "conditional_pick", "suite": "tavis_head", "split": "id", "n": 96, "successes": 39,
                      "success_rate": 0.40625, "ci_low": 0.3132, "ci_high": 0.5064, "galt_median_s": 0.8}],
           "sources": [{"source": "eval", "robots": ["gr1t2"], "camera_modes": ["head_wrist"]}]}


@pytest.fixture
def checkpoint(tmp_path):
    """<train output>/checkpoints/003200/pretrained_model: configs, weights, a processor file."""
    import json

    folder = tmp_path / "train" / "checkpoints" / "003200" / "pretrained_model"
    folder.mkdir(parents=True)
    images = {f"observation.images.{camera}": {"type": "VISUAL", "shape": [3, 120, 160]}
              for camera in ("head", "left_wrist", "right_wrist")}
    (folder / "config.json").write_text(json.dumps({"type": "act_hand_relative", "input_features": images}))
    (folder / "train_config.json").write_text(json.dumps(TRAIN_CONFIG))
    (folder / "model.safetensors").write_bytes(b"weights")
    (folder / "policy_preprocessor.json").write_text("{}")
    (tmp_path / "results.json").write_text(json.dumps(RESULTS))
    return folder


def test_policy_card_names_env_robot_task_cameras_data_recipe_commands_and_results(checkpoint):
    from lerobot_tavis.policy_hub import policy_card

    card = policy_card(checkpoint, POLICY_REPO, RESULTS)
    front_matter = card.split("---\n")[1]
    assert "library_name: lerobot" in front_matter and "- someone/tavis-head-gr1t2" in front_matter
    assert all(f"- {tag}\n" in front_matter for tag in ("lerobot", "tavis", "robotics", "act_hand_relative"))
    for text in ("| Policy | LeRobot `act_hand_relative` |", "`--env.type=tavis`", "| Task | `conditional_pick` |",
                 "| Robot | `gr1t2` |", "| Camera mode | `head_wrist` |",
                 "| Cameras read | `head`, `left_wrist`, `right_wrist` |", "| Image size | 120x160 (height x width) |",
                 "[`someone/tavis-head-gr1t2`](https://huggingface.co/datasets/someone/tavis-head-gr1t2)",
                 "| Recipe | preset `act_hand_relative_head_wrist_compact`; steps 3200, batch size 128, seed 1000 |",
                 f"lerobot-eval --policy.path={POLICY_REPO} --env.type=tavis --env.task=conditional_pick "
                 "--eval.n_episodes=96 --output_dir=outputs/eval/act_conditional_pick",
                 f"tavis eval --policy {POLICY_REPO} --tasks conditional_pick",
                 "lerobot-train --config_path=$(tavis presets act_hand_relative_head_wrist_compact) "
                 "--dataset.repo_id=someone/tavis-head-gr1t2 --env.task=conditional_pick --steps=3200 "
                 "--batch_size=128 --seed=1000",
                 "on gr1t2 with camera mode head_wrist",
                 "| `conditional_pick` | id | 96 | 40.6% | [31.3, 50.6] | 0.80 |",
                 "@misc{tavis,"):
        assert text in card, text
    assert "/data/tavis" not in card  # the machine's path stays private
    assert "## Results" not in policy_card(checkpoint, POLICY_REPO)


def test_push_policy_uploads_the_checkpoint_card_and_results_in_one_commit(checkpoint, hub, uploads, monkeypatch):
    from huggingface_hub import HfApi

    from lerobot_tavis.policy_hub import policy_card, push_policy

    staged = {}

    def upload_folder(self, *, folder_path, **kwargs):  # the staging folder is gone once the push returns
        staged.update({path.name: path.read_bytes() for path in Path(folder_path).iterdir()})
        uploads.append(("upload_folder", kwargs))

    monkeypatch.setattr(HfApi, "upload_folder", upload_folder)
    monkeypatch.setenv("HF_TOKEN", "hf_test")
    results = checkpoint.parents[2].parent / "results.json"
    url = push_policy(checkpoint, POLICY_REPO, results=results, private=True)
    assert url == f"{hub}/{POLICY_REPO}"
    assert [name for name, _ in uploads] == ["create_repo", "upload_folder"]
    calls = dict(uploads)
    assert calls["create_repo"]["repo_type"] == "model" and calls["create_repo"]["private"] is True
    assert calls["upload_folder"]["repo_type"] == "model" and calls["upload_folder"]["revision"] is None
    assert sorted(staged) == ["README.md", "config.json", "model.safetensors", "policy_preprocessor.json",
                              "results.json", "train_config.json"]
    assert staged["README.md"].decode() == policy_card(checkpoint, POLICY_REPO, RESULTS)
    assert staged["model.safetensors"] == b"weights" and staged["results.json"] == results.read_bytes()
    assert not (checkpoint / "README.md").exists()  # the checkpoint folder is left as it was


def test_push_policy_out_writes_the_upload_ready_folder_without_network_or_login(checkpoint, hub, uploads, tmp_path):
    from lerobot_tavis.policy_hub import policy_card, push_policy

    results, out = tmp_path / "results.json", tmp_path / "model"
    out.mkdir()
    (out / "stale.txt").write_text("from an older card")
    assert push_policy(checkpoint, POLICY_REPO, results=results, out=out) == str(out)
    assert not uploads  # no Hub call, and no token needed
    assert sorted(path.name for path in out.iterdir()) == ["README.md", "config.json", "model.safetensors",
                                                           "policy_preprocessor.json", "results.json",
                                                           "train_config.json"]
    assert (out / "README.md").read_text() == policy_card(checkpoint, POLICY_REPO, RESULTS)
    assert (out / "results.json").read_bytes() == results.read_bytes()
    assert not [path for path in tmp_path.iterdir() if path.name.startswith(".")]  # no staging copy left


def test_push_policy_refuses_before_uploading(checkpoint, hub, uploads, monkeypatch, tmp_path):
    from lerobot_tavis.policy_hub import push_policy

    with pytest.raises(HubError, match="not logged in"):
        push_policy(checkpoint, POLICY_REPO)
    monkeypatch.setenv("HF_TOKEN", "hf_test")
    train = checkpoint.parents[2]
    with pytest.raises(FileNotFoundError, match=f"{train} holds no config.json: pass {checkpoint}$"):
        push_policy(train, POLICY_REPO)
    (tmp_path / "other.json").write_text('{"per_task": []}')
    with pytest.raises(ValueError, match="other.json: not a `tavis report` results.json"):
        push_policy(checkpoint, POLICY_REPO, results=tmp_path / "other.json")
    (checkpoint / "model.safetensors").unlink()
    with pytest.raises(FileNotFoundError, match="holds no model.safetensors"):
        push_policy(checkpoint, POLICY_REPO)
    assert uploads == []


def test_tavis_push_policy_prints_the_models_url(checkpoint, hub, uploads, monkeypatch, capsys):
    from lerobot_tavis.cli import main

    monkeypatch.setenv("HF_TOKEN", "hf_test")
    main(["push-policy", str(checkpoint), "--repo-id", POLICY_REPO, "--branch", "step/3200"])
    assert capsys.readouterr().out.strip() == f"{hub}/{POLICY_REPO}/tree/step%2F3200"
    calls = dict(uploads)
    assert calls["create_branch"]["branch"] == "step/3200" and calls["upload_folder"]["revision"] == "step/3200"
