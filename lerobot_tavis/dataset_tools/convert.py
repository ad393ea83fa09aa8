"""`tavis convert`: replay raw episodes, render the cameras and write a LeRobotDataset v3.0.

Each raw episode is replayed from its seed with its recorded 60 Hz actions. Every (60 / fps)-th step becomes a
frame: the observation at that step (images, measured canonical state, joint positions) with the last 60 Hz action
of the frame's interval, the command in force when the next frame is observed. This is the pairing the reference
trains on (its +1 action shift, docs/reference.md §11): a 20 Hz policy holds each action for three ticks, and
holding the interval's first command instead leaves the hands lagging the recording, a few millimetres under the
lift line at the end of a demonstration (`tavis verify-dataset` measures it).

The replay must end as the recording did (success and length), else the conversion stops with an error; the
largest joint-state deviation from the recorded states is kept per episode in `meta/tavis_conversion.json`.
`workers` processes replay and render episodes side by side; this process writes them in a fixed order (task, then
seed), so the dataset does not depend on the number of workers. Videos are encoded while frames arrive.
The dataset is written beside its destination and moved into place only when complete.
"""

from __future__ import annotations

import json
import os
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_tavis import canonical, checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.dataset_tools import features as ft
from lerobot_tavis.dataset_tools.quiet import quiet_media_libraries
from lerobot_tavis.dataset_tools.raw import Manifest, RawEpisode, RawEpisodeError, load_episode
from lerobot_tavis.envs.tasks.catalog import task_sort_key
from lerobot_tavis.errors import FieldError, InputError, TavisError
from lerobot_tavis.locking import exclusive_output
from lerobot_tavis.process import without_realtime_priority
from lerobot_tavis.staging import staged_directory
from lerobot_tavis.workers import executor

CONVERSION_LOG = "meta/tavis_conversion.json"
RAW_IMAGE_SIZE = (480, 640)  # (H, W) of the cameras rendered from raw episodes unless told otherwise
RENDER_SHADOWS = True  # replayed episodes are rendered with the key light's shadows, as evaluation renders them


class ReplayError(TavisError):
    """A replay did not reproduce its recording."""


@dataclass(frozen=True)
class ConvertConfig:
    """What `tavis convert` converts, and how; also its command-line options. The source is `raw_dir` (a `tavis
    record` output) or `from_tavis` (an original TAVIS dataset, `dataset_tools.from_tavis`), exactly one; the
    storage, neck and worker settings apply to raw episodes only. `image_size` None: RAW_IMAGE_SIZE for raw
    episodes, the source size for an original dataset."""

    raw_dir: Path | None = option(help="a `tavis record` output directory", positional=True)
    from_tavis: Path | None = option(None, "convert an original TAVIS dataset (60 Hz) instead (default: none, "
                                     "convert RAW_DIR)", metavar="ROOT", kw_only=True)
    repo_id: str = option(help="dataset id, e.g. <user>/tavis-head-gr1t2")
    root: Path = option(help="destination directory (must not exist unless --overwrite)")
    fps: int = option(20, "dataset rate; must divide 60 (default 20)")
    image_size: tuple[int, int] | None = option(None, "HxW of every camera (default 480x640; --from-tavis: the "
                                                "source size)", parse=checks.image_size_text)
    cameras: tuple[str, ...] = option(ft.CAMERAS, f"comma list of cameras (default: {','.join(ft.CAMERAS)})",
                                      parse=ft.parse_cameras)
    task: str | None = option(None, "convert only this task (default: every task)")
    overwrite: bool = option(False, "replace an existing destination")
    storage: str = option("av1", "camera frames as AV1 video (LeRobot's default, smallest), all-intra H.264 video "
                          "(fast random access for training) or PNG images (no video decoding; largest)",
                          choices=ft.STORAGES)
    zero_neck: bool = option(False, "neck dims of state and action = 0 (datasets for the fixed-camera presets)")
    workers: int = option(1, "processes replaying and rendering episodes (the dataset does not depend on it)")

    def __post_init__(self):
        if (self.raw_dir is None) == (self.from_tavis is None):
            raise InputError("give exactly one of RAW_DIR (a `tavis record` output) and --from-tavis ROOT")
        if self.from_tavis is not None and (self.zero_neck or self.storage != "av1"):
            raise InputError("--zero-neck and --storage apply to raw episodes, not to --from-tavis")
        checks.repo_id(self.repo_id)
        _check_root_apart(self.root, self.raw_dir if self.from_tavis is None else self.from_tavis)
        if self.raw_dir is not None:
            object.__setattr__(self, "image_size", checks.image_size(
                RAW_IMAGE_SIZE if self.image_size is None else self.image_size))
            checks.integer("workers", self.workers, 1)


def _check_root_apart(root: Path, source: Path) -> None:
    """Refuse a destination that is the source, inside it or above it: replacing it (--overwrite) would delete the
    episodes being read, and a dataset inside a raw directory mixes the two. Compared after resolving links."""
    root_at, source_at = Path(root).resolve(), Path(source).resolve()
    if root_at == source_at or source_at in root_at.parents or root_at in source_at.parents:
        where = ("is" if root_at == source_at else "is inside" if source_at in root_at.parents else "holds")
        raise FieldError("root", f"{root} {where} the input {source}: a conversion never writes where it reads; give a "
                                 "destination outside it")


def convert(cfg: ConvertConfig, progress: bool = True) -> Path:
    """Convert `cfg.raw_dir` (or `cfg.from_tavis`) into a LeRobotDataset at `cfg.root`; returns the root. One
    conversion at a time per root (`locking`): another one converting into it is refused, naming it. The video
    encoders run at normal priority (`process.without_realtime_priority`), also where the process is root."""
    with exclusive_output(cfg.root), without_realtime_priority():
        return _convert(cfg, progress)


def _convert(cfg: ConvertConfig, progress: bool) -> Path:
    if cfg.from_tavis is not None:
        from lerobot_tavis.dataset_tools.from_tavis import convert_from_tavis

        return convert_from_tavis(cfg.from_tavis, cfg.repo_id, cfg.root, fps=cfg.fps, image_size=cfg.image_size,
                                  overwrite=cfg.overwrite, task=cfg.task, progress=progress)
    os.environ.setdefault("MUJOCO_GL", "egl")
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_tavis.envs.robots import make_robot

    quiet_media_libraries()

    cameras = ft.parse_cameras(cfg.cameras)
    manifest = Manifest.load(cfg.raw_dir)
    stride = ft.frame_stride(manifest.fps, cfg.fps)
    entries = sorted((e for e in manifest.episodes if cfg.task in (None, e.task)),
                     key=lambda e: (task_sort_key(e.task), e.seed))
    if not entries:
        raise InputError(f"{cfg.raw_dir} holds no episodes" + (f" of task {cfg.task!r}" if cfg.task else ""))
    damaged = manifest.damaged(cfg.raw_dir)
    if damaged:
        listing = ", ".join(f"{file} ({problem})" for file, problem in damaged.items())
        raise RawEpisodeError(f"{cfg.raw_dir}: raw episodes that cannot be trusted, nothing converted: {listing}")
    features = ft.dataset_features(make_robot(manifest.robot).joint_names(), cameras, cfg.image_size, cfg.storage)
    deviations = {}
    with staged_directory(cfg.root, overwrite=cfg.overwrite) as staging:
        videos = cfg.storage != "png"
        # LeRobot's streaming encoder drops frames when its queue is full (it is made for live capture, where a
        # lagging encoder must not stall the robot); offline, every frame must reach the video, so the queue is
        # unbounded (0): at most one episode's frames wait in memory.
        dataset = LeRobotDataset.create(cfg.repo_id, fps=cfg.fps, features=features, root=staging,
                                        robot_type=manifest.robot, use_videos=videos, video_backend="pyav",
                                        rgb_encoder=ft.video_encoder(cfg.storage), streaming_encoding=videos,
                                        encoder_queue_maxsize=0)
        episodes = replayed(cfg, entries, cameras, stride)
        try:
            for entry, frames, deviation in tqdm(episodes, total=len(entries), desc=f"convert {cfg.repo_id}",
                                                 unit="ep", disable=not progress):
                for frame in frames:
                    dataset.add_frame(frame)
                dataset.save_episode()
                deviations[entry.file] = deviation
        finally:
            episodes.close()  # stops the workers at once when a replay or a write failed
            dataset.finalize()  # also on failure: an unfinalized dataset writes into the staging folder later
        log = {"raw_dir": str(Path(cfg.raw_dir).absolute()), "fps": cfg.fps, "stride": stride, "storage": cfg.storage,
               "image_size": list(cfg.image_size), "shadows": RENDER_SHADOWS, "cameras": list(cameras),
               "zero_neck": cfg.zero_neck,
               "episodes": [{"episode_index": i, "raw_file": e.file, "task": e.task, "seed": e.seed,
                             "max_qpos_deviation": deviations[e.file]} for i, e in enumerate(entries)]}
        (staging / CONVERSION_LOG).write_text(json.dumps(log, indent=1) + "\n")
    return Path(cfg.root)


def replayed(cfg: ConvertConfig, entries: Sequence, cameras: Sequence[str],
             stride: int) -> Iterator[tuple[object, list[dict], float]]:
    """(entry, frames, largest joint-state deviation) of each entry, in order, replayed by `cfg.workers` processes.

    At most two episodes per worker are in flight or waiting, which bounds the memory their frames take.
    """
    pending = deque()
    with executor(cfg.workers) as pool:
        try:
            for entry in entries:
                pending.append((entry, pool.submit(replay_episode, Path(cfg.raw_dir) / entry.file, entry.sha256,
                                                   tuple(cameras), cfg.image_size, stride, cfg.zero_neck)))
                if len(pending) >= 2 * cfg.workers:
                    entry, future = pending.popleft()
                    yield entry, *future.result()
            while pending:
                entry, future = pending.popleft()
                yield entry, *future.result()
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
            close_replayers()  # those of this process (workers == 1); a worker's go with its process


_REPLAYERS: dict[tuple, Replayer] = {}  # per process: (cameras, image_size, stride, zero_neck) -> its replayer


def replay_episode(path: Path, sha256: str, cameras: tuple[str, ...], image_size: tuple[int, int], stride: int,
                   zero_neck: bool) -> tuple[list[dict], float]:
    """The frames of one raw episode and the replay's largest joint-state deviation (rad or m) from the recording."""
    key = (cameras, tuple(image_size), stride, zero_neck)
    if key not in _REPLAYERS:
        _REPLAYERS[key] = Replayer(cameras, image_size, stride, zero_neck)
    replayer = _REPLAYERS[key]
    frames = list(replayer.frames(load_episode(path, sha256)))
    return frames, replayer.max_deviation


def close_replayers() -> None:
    while _REPLAYERS:
        _REPLAYERS.popitem()[1].close()


class Replayer:
    """Replays raw episodes in one env per task, rendering `cameras` at every `stride`-th step."""

    def __init__(self, cameras: Sequence[str], image_size: tuple[int, int], stride: int, zero_neck: bool = False):
        self.cameras = tuple(cameras)
        self.zero_neck = zero_neck
        self.image_size = image_size
        self.stride = stride
        self.max_deviation = 0.0
        self._envs: dict[tuple[str, str, str], object] = {}  # (robot, task, split) -> env
        self._rigs: dict[tuple[str, str, str], object] = {}  # ... -> its camera rig (made after its first reset)

    def frames(self, episode: RawEpisode) -> Iterator[dict]:
        """The LeRobot frames of one episode, replaying it; raises ReplayError if it does not end as recorded."""
        env = self._env(episode)
        obs, _ = env.reset(seed=episode.seed)
        rig = self._rig(episode, env)
        if env.task_description != episode.prompt:
            raise ReplayError(f"{episode.task} seed {episode.seed}: the replay's prompt {env.task_description!r} "
                              f"differs from the recorded {episode.prompt!r}")
        self.max_deviation = float(np.max(np.abs(env.data.qpos - episode.qpos[0])))
        info, ended_at = {"is_success": False}, None
        for step, action in enumerate(episode.actions):
            if ended_at is not None:
                break
            if step % self.stride == 0:
                last_in_interval = episode.actions[min(step + self.stride, len(episode.actions)) - 1]
                yield self._frame(episode, rig.render(env.data), obs, last_in_interval)
            obs, _, terminated, truncated, info = env.step(action)
            self.max_deviation = max(self.max_deviation, float(np.max(np.abs(env.data.qpos - episode.qpos[step + 1]))))
            if terminated or truncated:
                ended_at = step + 1
        if (bool(info["is_success"]), ended_at or episode.n_steps) != (episode.success, episode.n_steps):
            raise ReplayError(
                f"{episode.task} seed {episode.seed}: the replay ended with success={info['is_success']} after "
                f"{ended_at or episode.n_steps} steps, the recording with success={episode.success} after "
                f"{episode.n_steps} (largest joint-state deviation {self.max_deviation:.3g})")

    def _frame(self, episode: RawEpisode, images: dict, obs: dict, action: np.ndarray) -> dict:
        frame = {ft.image_key(camera): image for camera, image in images.items()}
        frame[ft.STATE_KEY] = obs["agent_pos"].astype(np.float32)
        frame[ft.JOINT_POS_KEY] = obs["joint_pos"].astype(np.float32)
        frame[ft.ACTION_KEY] = np.asarray(action, dtype=np.float32)
        if self.zero_neck:
            frame[ft.STATE_KEY][canonical.HEAD] = 0.0
            frame[ft.ACTION_KEY][canonical.HEAD] = 0.0
        frame[ft.TASK_NAME_KEY] = episode.task
        frame[ft.SPLIT_KEY] = episode.split
        frame["task"] = episode.prompt
        return frame

    def _env(self, episode: RawEpisode):
        """The env of the episode's robot, task and split; it renders nothing itself."""
        from lerobot_tavis.envs.env import TavisEnv

        key = (episode.robot, episode.task, episode.split)
        if key not in self._envs:
            self._envs[key] = TavisEnv(episode.task, episode.robot, split=episode.split, fps=episode.fps,
                                       image_size=self.image_size, shadows=RENDER_SHADOWS, cameras=())
        return self._envs[key]

    def _rig(self, episode: RawEpisode, env):
        """The rig rendering the requested cameras from `env` (which must have been reset once)."""
        from lerobot_tavis.envs.rendering import CameraRig

        key = (episode.robot, episode.task, episode.split)
        if key not in self._rigs:
            self._rigs[key] = CameraRig(env.model, {name: env.world.cameras[name] for name in self.cameras},
                                        self.image_size, env.task_object.blacked_out_cameras)
        return self._rigs[key]

    def close(self) -> None:
        for rig in self._rigs.values():
            rig.close()
        for env in self._envs.values():
            env.close()
