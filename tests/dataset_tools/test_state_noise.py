"""`tavis noise-state`: a copy of a dataset with Gaussian noise on the hand poses of `observation.state`, on a small
synthetic LeRobotDataset (random canonical states, one tiny video camera)."""

import hashlib
import json
import math
import shutil

import numpy as np
import pandas as pd
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.cli import main
from lerobot_tavis.dataset_tools import features as ft
from lerobot_tavis.dataset_tools import state_noise
from lerobot_tavis.dataset_tools.state_noise import NOISE_RECORD, write_state_noise_copy
from lerobot_tavis.errors import FieldError, InputError, PathExistsError, PathNotFoundError

EPISODES, LENGTH = 4, 150  # 600 frames, 1200 hand poses: sample deviations within a few % of the requested sigma
SIZE = (24, 32)
POSITION_M, ROTATION_DEG = 0.02, 5.0
ARM_SLOTS = np.r_[canonical.LEFT.position, canonical.LEFT.quaternion, canonical.RIGHT.position,
                  canonical.RIGHT.quaternion]
EXACT_SLOTS = np.setdiff1d(np.arange(canonical.ACTION_DIM), ARM_SLOTS)  # head and grippers


def random_states(rng, n: int) -> np.ndarray:
    """n canonical states: hands around their rest positions, random unit quaternions with w >= 0."""
    states = np.tile(canonical.rest_action(), (n, 1))
    for arm in canonical.ARMS:
        states[:, arm.position] += rng.uniform(-0.1, 0.1, (n, 3))
        quats = rng.normal(size=(n, 4))
        quats /= np.linalg.norm(quats, axis=1, keepdims=True)
        states[:, arm.quaternion] = quats * np.sign(quats[:, :1])
    states[:, canonical.HEAD] = rng.uniform(-0.5, 0.5, (n, 3))
    states[:, [canonical.LEFT.gripper, canonical.RIGHT.gripper]] = rng.uniform(-1, 1, (n, 2))
    return states.astype(np.float32)


def digest(root) -> dict[str, str]:
    return {str(path.relative_to(root)): hashlib.sha256(path.read_bytes()).hexdigest()
            for path in sorted(root.rglob("*")) if path.is_file()}


def frames(root) -> pd.DataFrame:
    table = pd.concat([pd.read_parquet(path) for path in sorted((root / "data").rglob("*.parquet"))])
    return table.sort_values("index").reset_index(drop=True)


def states(root) -> np.ndarray:
    return np.stack(frames(root)[ft.STATE_KEY].to_numpy()).astype(np.float64)


def no_leftovers(destination) -> bool:
    return not [path.name for path in destination.parent.iterdir() if path.name.startswith(f".{destination.name}.")]


@pytest.fixture(scope="module")
def source(tmp_path_factory):
    """A LeRobotDataset v3.0 in the TAVIS schema: EPISODES episodes of LENGTH frames at 20 Hz, head camera only."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    root = tmp_path_factory.mktemp("state_noise") / "source"
    rng = np.random.default_rng(7)
    dataset = LeRobotDataset.create("local/source", fps=20, features=ft.dataset_features(["j0", "j1"], ("head",), SIZE),
                                    root=root, robot_type="gr1t2", use_videos=True)
    for episode in range(EPISODES):
        for state, action in zip(random_states(rng, LENGTH), random_states(rng, LENGTH)):
            dataset.add_frame({ft.image_key("head"): rng.integers(0, 255, (*SIZE, 3), dtype=np.uint8),
                               ft.STATE_KEY: state, ft.JOINT_POS_KEY: rng.normal(size=2).astype(np.float32),
                               ft.ACTION_KEY: action, ft.TASK_NAME_KEY: "conditional_pick", ft.SPLIT_KEY: "id",
                               "task": "pick"})
        dataset.save_episode()
    dataset.finalize()
    return root


@pytest.fixture(scope="module")
def source_digest(source):
    return digest(source)


@pytest.fixture(scope="module")
def noisy(source, source_digest, tmp_path_factory):
    out = tmp_path_factory.mktemp("noisy") / "copy"
    summary = write_state_noise_copy(source, out, POSITION_M, ROTATION_DEG, seed=0)
    return out, summary


def rotation_vectors(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """Rotation vectors (rad) of the rotations r with after = r * before (quaternions w, x, y, z)."""
    bw, bv, aw, av = before[:, :1], -before[:, 1:], after[:, :1], after[:, 1:]  # before conjugated
    w = aw * bw - np.sum(av * bv, axis=1, keepdims=True)
    v = aw * bv + bw * av + np.cross(av, bv)
    v, w = v * np.sign(w), np.abs(w)
    norm = np.linalg.norm(v, axis=1, keepdims=True)
    return v / norm * 2 * np.arctan2(norm, w)


def test_the_hand_poses_carry_noise_of_the_requested_scale(source, noisy):
    out, summary = noisy
    before, after = states(source), states(out)
    rotation_rad = math.radians(ROTATION_DEG)
    for arm in canonical.ARMS:
        shift = after[:, arm.position] - before[:, arm.position]
        assert 0.9 * POSITION_M < shift.std() < 1.1 * POSITION_M
        assert np.abs(shift.mean(axis=0)).max() < 4 * POSITION_M / math.sqrt(len(shift))
        quats = after[:, arm.quaternion]
        assert np.allclose(np.linalg.norm(quats, axis=1), 1, atol=1e-6) and (quats[:, 0] >= 0).all()
        rotvecs = rotation_vectors(before[:, arm.quaternion], quats)
        assert 0.9 * rotation_rad < rotvecs.std() < 1.1 * rotation_rad
        assert np.abs(rotvecs.mean(axis=0)).max() < 4 * rotation_rad / math.sqrt(len(rotvecs))
        assert np.linalg.norm(rotvecs, axis=1).min() > 1e-4  # every frame turned
    # The measured means: E|x| = 2 sigma sqrt(2 / pi) for a 3-D normal x of sigma per component.
    maxwell = 2 * math.sqrt(2 / math.pi)
    assert summary.frames == summary.frames_changed == EPISODES * LENGTH
    assert 0.9 * maxwell * 1000 * POSITION_M < summary.mean_position_shift_mm < 1.1 * maxwell * 1000 * POSITION_M
    assert 0.9 * maxwell * ROTATION_DEG < summary.mean_rotation_deg < 1.1 * maxwell * ROTATION_DEG
    assert json.loads((out / NOISE_RECORD).read_text()) == {
        "source_root": str(source), "position_m": POSITION_M, "rotation_deg": ROTATION_DEG, "seed": 0,
        "frames": summary.frames, "frames_changed": summary.frames_changed, "quaternion_sign": "w >= 0",
        "mean_position_shift_mm": summary.mean_position_shift_mm, "mean_rotation_deg": summary.mean_rotation_deg}


def test_everything_but_the_hand_poses_is_bit_identical(source, noisy):
    out, _ = noisy
    before, after = frames(source), frames(out)
    assert list(before.columns) == list(after.columns) and len(before) == len(after)
    for column in before.columns.drop(ft.STATE_KEY):
        as_bytes = [table[column].map(lambda value: np.asarray(value).tobytes()) for table in (before, after)]
        assert as_bytes[0].equals(as_bytes[1]), column
    exact = [np.stack(table[ft.STATE_KEY].to_numpy())[:, EXACT_SLOTS] for table in (before, after)]
    assert exact[0].tobytes() == exact[1].tobytes()
    unchanged = {path: sha for path, sha in digest(source).items()
                 if not path.startswith(("data/", "meta/episodes/")) and path != "meta/stats.json"}
    assert {path: digest(out)[path] for path in unchanged} == unchanged  # videos, info, tasks
    (video,) = (source / "videos").rglob("*.mp4")
    assert (out / video.relative_to(source)).samefile(video)  # hard-linked on one filesystem


def test_stats_describe_the_new_states_as_lerobot_writes_them(source, noisy):
    out, _ = noisy
    new, stats = states(out), json.loads((out / "meta/stats.json").read_text())
    old_stats = json.loads((source / "meta/stats.json").read_text())
    entry = {key: np.asarray(value) for key, value in stats[ft.STATE_KEY].items()}
    assert list(entry) == list(old_stats[ft.STATE_KEY])  # min, max, mean, std, count, q01 ... q99
    assert np.array_equal(entry["min"], new.min(axis=0)) and np.array_equal(entry["max"], new.max(axis=0))
    assert np.allclose(entry["mean"], new.mean(axis=0), atol=1e-6)
    assert np.allclose(entry["std"], new.std(axis=0), atol=1e-5)
    assert entry["count"].tolist() == [len(new)]
    assert (entry["min"] <= entry["q01"]).all() and (entry["q01"] <= entry["q50"]).all()
    assert (entry["q50"] <= entry["q99"]).all() and (entry["q99"] <= entry["max"]).all()
    assert not np.allclose(entry["std"], old_stats[ft.STATE_KEY]["std"])
    assert {key: value for key, value in stats.items() if key != ft.STATE_KEY} == \
        {key: value for key, value in old_stats.items() if key != ft.STATE_KEY}
    episodes = pd.concat(pd.read_parquet(path) for path in sorted((out / "meta/episodes").rglob("*.parquet")))
    table = frames(out)
    for _, row in episodes.iterrows():
        mine = np.stack(table[table.episode_index == row.episode_index][ft.STATE_KEY].to_numpy())
        assert np.array_equal(row[f"stats/{ft.STATE_KEY}/max"], mine.max(axis=0))
        assert np.allclose(row[f"stats/{ft.STATE_KEY}/mean"], mine.mean(axis=0), atol=1e-6)


def test_the_copy_loads_with_lerobot(noisy):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    out, _ = noisy
    dataset = LeRobotDataset("local/noisy", root=out, video_backend="pyav")
    assert dataset.num_frames == EPISODES * LENGTH and dataset.num_episodes == EPISODES
    item = dataset[LENGTH + 3]
    assert np.array_equal(item[ft.STATE_KEY].numpy(), states(out)[LENGTH + 3].astype(np.float32))
    assert tuple(item[ft.image_key("head")].shape) == (3, *SIZE)
    assert np.array_equal(dataset.meta.stats[ft.STATE_KEY]["max"], states(out).max(axis=0))


def test_the_same_seed_makes_the_same_copy_and_another_seed_another(source, noisy, tmp_path):
    out, _ = noisy
    write_state_noise_copy(source, tmp_path / "again", POSITION_M, ROTATION_DEG, seed=0)
    write_state_noise_copy(source, tmp_path / "other", POSITION_M, ROTATION_DEG, seed=1)
    assert digest(tmp_path / "again") == digest(out)
    assert not (states(tmp_path / "other") == states(out)).all(axis=1).any()  # no frame's state alike


def test_the_command_prints_one_summary_line(source, tmp_path, capsys):
    out = tmp_path / "cli"
    main(["noise-state", str(source), "--out", str(out), "--position-m", "0.01", "--rotation-deg", "2", "--seed",
          "3"])
    record = json.loads((out / NOISE_RECORD).read_text())
    assert (record["position_m"], record["rotation_deg"], record["seed"]) == (0.01, 2.0, 3)
    assert capsys.readouterr().out == (
        f"{out}: {EPISODES * LENGTH} of {EPISODES * LENGTH} frames changed; hands moved "
        f"{record['mean_position_shift_mm']:.1f} mm and turned {record['mean_rotation_deg']:.2f} deg on average\n")
    with pytest.raises(SystemExit, match="--position-m must be a finite number >= 0, got -0.01"):
        main(["noise-state", str(source), "--out", str(tmp_path / "bad"), "--position-m", "-0.01", "--rotation-deg",
              "2"])


def _edit_info(root, edit) -> None:
    info = json.loads((root / "meta/info.json").read_text())
    edit(info)
    (root / "meta/info.json").write_text(json.dumps(info))


@pytest.mark.parametrize("case,error,match", [
    ("negative position", FieldError, "position_m must be a finite number >= 0, got -0.1"),
    ("nan rotation", FieldError, "rotation_deg must be a finite number >= 0, got nan"),
    ("negative seed", FieldError, "seed must be an integer >= 0, got -1"),
    ("missing source", PathNotFoundError, "source_root .*missing is not a directory"),
    ("not a dataset", PathNotFoundError, r"meta/info.json: missing \(.* is not a LeRobotDataset\)"),
    ("older version", InputError, "is a LeRobotDataset v2.1, not v3.0"),
    ("state of 18", InputError, r"observation.state must be float32 of shape \(19,\)"),
    ("no state", InputError, r"observation.state must be .* got no such feature"),
    ("noisy source", InputError, "is already a noisy copy"),
    ("existing out", PathExistsError, "out_root .*out already exists"),
    ("out inside source", FieldError, "out_root must lie outside source_root"),
])
def test_bad_input_is_refused_and_nothing_is_written(source, noisy, tmp_path, case, error, match):
    scale, seed, src, out = [POSITION_M, ROTATION_DEG], 0, tmp_path / "src", tmp_path / "out"
    if case in ("state of 18", "no state", "older version", "not a dataset", "out inside source"):
        shutil.copytree(source, src)
    if case == "negative position":
        scale[0], src = -0.1, source
    elif case == "nan rotation":
        scale[1], src = math.nan, source
    elif case == "negative seed":
        seed, src = -1, source
    elif case == "missing source":
        src = tmp_path / "missing"
    elif case == "not a dataset":
        (src / "meta/info.json").unlink()
    elif case == "older version":
        _edit_info(src, lambda info: info.update(codebase_version="v2.1"))
    elif case == "state of 18":
        _edit_info(src, lambda info: info["features"][ft.STATE_KEY].update(shape=[18]))
    elif case == "no state":
        _edit_info(src, lambda info: info["features"].pop(ft.STATE_KEY))
    elif case == "noisy source":
        src = noisy[0]
    elif case == "existing out":
        src = source
        out.mkdir()
    elif case == "out inside source":
        out = src / "noisy"
    before = sorted(tmp_path.iterdir())
    with pytest.raises(error, match=match):
        write_state_noise_copy(src, out, *scale, seed=seed)
    assert sorted(tmp_path.iterdir()) == before and no_leftovers(out)
    assert case == "existing out" or not out.exists()


def test_a_failure_while_writing_leaves_nothing(source, tmp_path, monkeypatch):
    def fail(*args):
        raise RuntimeError("disk full")

    monkeypatch.setattr(state_noise, "_rewrite_state_stats", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        write_state_noise_copy(source, tmp_path / "out", POSITION_M, ROTATION_DEG)
    assert list(tmp_path.iterdir()) == []


def test_the_source_is_untouched(source, source_digest, noisy):
    assert digest(source) == source_digest
