"""`tavis teleop`: a person drives the canonical 19-D action with the keyboard and records raw episodes exactly as
`tavis record` writes them (60 Hz applied actions and simulator states, a manifest with checksums), so
`tavis convert` turns them into a LeRobotDataset.

Keys, in MuJoCo's viewer window (the view follows the head camera unless `--view` says otherwise):

    W / S       active hand forward / back      (canonical x, HAND_STEP_M per press)
    A / D       active hand left / right        (canonical y)
    Q / E       active hand up / down           (canonical z)
    TAB         switch the active hand (the right hand starts)
    SPACE       close / open the active hand's gripper
    arrows      head pitch (up / down) and yaw (left / right), HEAD_STEP_RAD per press
    0           both hands and the head back to rest, grippers open
    ENTER       end the episode (kept if it succeeded, or with --keep-failures)
    BACKSPACE   drop the episode; the next one starts with the next seed

With `--gamepad`, LeRobot's gamepad controller (`lerobot.teleoperators.gamepad`, which needs pygame) moves the
active hand too: the left stick in the horizontal plane and the right stick vertically, GAMEPAD_SPEED_M_S at full
deflection; its close/open buttons drive the active gripper; its success and failure buttons end the episode and
its re-record button drops it. The keyboard keeps the head and the hand switch.

An episode also ends when the task succeeds or its time runs out, as a demonstrator's does. Seeds start at
`--seed-start` (200000 by default, away from the demonstrators' 100000 and the evaluation's 1000). The window shows
the key map (top left) and the episode's state (bottom left): seed, clock, active hand and gripper, episodes kept,
and how the last episode ended; each ending is also printed as it happens, saying whether the episode was kept.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lerobot_tavis import canonical, checks
from lerobot_tavis.cli_options import option
from lerobot_tavis.envs.robots import DEFAULT_ROBOT, robot_names
from lerobot_tavis.envs.tasks.catalog import split_names, task_names
from lerobot_tavis.errors import TavisError
from lerobot_tavis.locking import exclusive_output
from lerobot_tavis.viewer import (KEY_BACKSPACE, KEY_DOWN, KEY_ENTER, KEY_LEFT, KEY_RIGHT, KEY_SPACE, KEY_TAB, KEY_UP,
                                  WINDOW_CAMERAS)

HAND_STEP_M = 0.01
HEAD_STEP_RAD = 0.05
GAMEPAD_SPEED_M_S = 0.3
HAND_KEYS = {ord("W"): (0, +1), ord("S"): (0, -1), ord("A"): (1, +1), ord("D"): (1, -1),
             ord("Q"): (2, +1), ord("E"): (2, -1)}  # key -> (canonical axis, sign)
HEAD_KEYS = {KEY_UP: (canonical.HEAD_PITCH, -1), KEY_DOWN: (canonical.HEAD_PITCH, +1),
             KEY_LEFT: (canonical.HEAD_YAW, +1), KEY_RIGHT: (canonical.HEAD_YAW, -1)}  # +pitch looks down
END, DROP = "end", "drop"
KEY_MAP = (("W / S", "hand forward / back"), ("A / D", "hand left / right"), ("Q / E", "hand up / down"),
           ("TAB", "switch hand"), ("SPACE", "close / open gripper"), ("arrows", "head pitch / yaw"),
           ("0", "back to rest"), ("ENTER", "end episode"), ("BACKSPACE", "drop episode"))  # drawn in the window


class NoGamepadError(TavisError):
    """--gamepad was asked for, but pygame or the gamepad itself is missing."""


@dataclass
class TeleopCommand:
    """The canonical action a person is holding, changed one key press at a time."""

    action: np.ndarray = field(default_factory=canonical.rest_action)
    hand: canonical.ArmSlots = canonical.RIGHT

    def press(self, key: int) -> str | None:
        """Apply one key press; returns END or DROP for the episode keys, None otherwise (unknown keys too)."""
        if key in HAND_KEYS:
            axis, sign = HAND_KEYS[key]
            self.action[self.hand.position.start + axis] += sign * HAND_STEP_M
        elif key in HEAD_KEYS:
            index, sign = HEAD_KEYS[key]
            self.action[index] += sign * HEAD_STEP_RAD
        elif key == KEY_TAB:
            self.hand = canonical.LEFT if self.hand is canonical.RIGHT else canonical.RIGHT
        elif key == KEY_SPACE:
            closed = self.action[self.hand.gripper] > 0
            self.action[self.hand.gripper] = canonical.GRIPPER_OPEN if closed else canonical.GRIPPER_CLOSED
        elif key == ord("0"):
            self.action = canonical.rest_action()
        elif key == KEY_ENTER:
            return END
        elif key == KEY_BACKSPACE:
            return DROP
        return None

    def move_hand(self, delta_m) -> None:
        """Move the active hand by (dx, dy, dz) m in the canonical frame."""
        self.action[self.hand.position] += np.asarray(delta_m, dtype=float)

    def set_gripper(self, closed: bool) -> None:
        self.action[self.hand.gripper] = canonical.GRIPPER_CLOSED if closed else canonical.GRIPPER_OPEN


def apply_gamepad(command: TeleopCommand, controller) -> str | None:
    """Read one tick of a LeRobot `InputController` (`lerobot.teleoperators.gamepad.gamepad_utils`) into
    `command`: its deltas move the active hand, its gripper command closes or opens it. Returns END for its success
    or failure event, DROP for re-record, None otherwise."""
    from lerobot.teleoperators.utils import TeleopEvents

    controller.update()
    command.move_hand(controller.get_deltas())
    gripper = controller.gripper_command()
    if gripper in ("close", "open"):
        command.set_gripper(gripper == "close")
    status = controller.get_episode_end_status()
    if status in (TeleopEvents.SUCCESS, TeleopEvents.FAILURE):
        return END
    if status == TeleopEvents.RERECORD_EPISODE:
        return DROP
    return None


def lerobot_gamepad():
    """LeRobot's pygame gamepad controller, started, with steps of GAMEPAD_SPEED_M_S at the 60 Hz record rate."""
    from lerobot.teleoperators.gamepad.gamepad_utils import GamepadController

    step = GAMEPAD_SPEED_M_S / 60
    try:
        controller = GamepadController(x_step_size=step, y_step_size=step, z_step_size=step)
    except ImportError as error:  # LeRobot's message names the extra that brings pygame
        raise NoGamepadError(f"--gamepad: {error}") from None
    controller.start()
    if not controller.running:
        raise NoGamepadError("--gamepad: no gamepad found; connect one, or leave out --gamepad for the keyboard alone")
    return controller


@dataclass(frozen=True, kw_only=True)
class TeleopConfig:
    """What `tavis teleop` records, and where; also its command-line options."""

    task: str = option(choices=task_names)
    robot: str = option(DEFAULT_ROBOT, choices=robot_names)
    split: str = option("id", choices=split_names)
    episodes: int = option(1, "kept episodes to record (default 1)")
    seed_start: int = option(200_000, "first seed (default 200000)")
    keep_failures: bool = option(False, "keep episodes that did not succeed too")
    view: str = option("head", "the window's camera (default head)", choices=WINDOW_CAMERAS)
    gamepad: bool = option(False, "also drive the active hand with a gamepad (LeRobot's controller; needs pygame)")
    out_dir: Path = option(help="raw directory, as `tavis record` writes; re-running adds to it", flag="--out")

    def __post_init__(self):
        checks.integer("episodes", self.episodes, 1)
        checks.integer("seed_start", self.seed_start, 0)


def key_map_columns() -> tuple[str, str]:
    """The key map as two text columns (keys, what they do), one line per key."""
    return "\n".join(key for key, _ in KEY_MAP), "\n".join(does for _, does in KEY_MAP)


def episode_state_columns(seed: int, time_s: float, duration_s: float, command: TeleopCommand, kept: int,
                          wanted: int, last: str | None) -> tuple[str, str]:
    """What the window says about the episode under way, as two text columns (labels, values)."""
    gripper = "closed" if command.action[command.hand.gripper] > 0 else "open"
    rows = [("seed", str(seed)), ("time", f"{time_s:4.1f} / {duration_s:.0f} s"),
            ("hand", f"{command.hand.side}, gripper {gripper}"), ("kept", f"{kept} of {wanted}")]
    if last:
        rows.append(("last", last))
    return "\n".join(label for label, _ in rows), "\n".join(value for _, value in rows)


def teleop_episode(env, seed: int, keys: Callable[[], list[int]], show: Callable[[TeleopCommand, int], None],
                   gamepad=None):
    """One episode of `env` (a TavisEnv at the 60 Hz record rate) driven by the key presses `keys()` returns
    before each tick (and the `gamepad` controller, if any), `show(command, ticks)` after each. Returns (how it
    ended: END, DROP or None for success or time out, success, the applied actions, the StateLog of the episode)."""
    from lerobot_tavis.dataset_tools.record import StateLog

    env.reset(seed=seed)
    states, command, actions = StateLog(), TeleopCommand(), []
    states.snapshot(env)
    show(command, 0)
    for _ in range(env._max_episode_steps):
        ending = next((result for key in keys() if (result := command.press(key))), None)
        if gamepad is not None:
            ending = apply_gamepad(command, gamepad) or ending
        if ending:
            return ending, False, actions, states
        _, _, terminated, truncated, info = env.step(command.action)
        actions.append(info["applied_action"])
        states.snapshot(env)
        show(command, len(actions))
        if terminated or truncated:
            return None, bool(info["is_success"]), actions, states
    return None, False, actions, states


def outcome_line(seed: int, ending: str | None, success: bool, kept: bool, steps: int) -> str:
    """How one episode ended, and whether it was kept (and why not)."""
    if ending == DROP:
        return f"seed {seed}: dropped"
    why = "" if kept else "; --keep-failures keeps failed episodes"
    return f"seed {seed}: {'success' if success else 'failure'}, {'kept' if kept else 'not kept'} ({steps} steps{why})"


def teleop(cfg: TeleopConfig, keys: Callable[[], list[int]] | None = None,
           show: Callable[[TeleopCommand, int], None] | None = None, gamepad=None) -> Iterator[str]:
    """Record `cfg.episodes` kept episodes into `cfg.out_dir`, yielding each episode's outcome line as it ends.
    Without `keys` and `show` it opens the viewer window, which shows the key map and the episode's state, and with
    `cfg.gamepad` LeRobot's gamepad controller (tests pass scripted key presses and controllers instead). Holds the
    directory's lock (`locking`), as `tavis record` does."""
    with exclusive_output(cfg.out_dir):
        yield from _teleop(cfg, keys, show, gamepad)


def _teleop(cfg: TeleopConfig, keys: Callable[[], list[int]] | None,
            show: Callable[[TeleopCommand, int], None] | None, gamepad) -> Iterator[str]:
    from lerobot_tavis.dataset_tools.raw import ManifestEntry
    from lerobot_tavis.dataset_tools.record import RECORD_FPS, open_manifest, store_episode
    from lerobot_tavis.envs.env import TavisEnv
    from lerobot_tavis.viewer import Window, require_display

    if keys is None:
        require_display("tavis teleop")
    if cfg.gamepad and gamepad is None:
        gamepad = lerobot_gamepad()
    env = TavisEnv(cfg.task, cfg.robot, split=cfg.split, fps=RECORD_FPS, cameras=())
    manifest = open_manifest(cfg.out_dir, cfg.robot, cfg.split, cfg.seed_start, command="tavis teleop")
    seed = max(manifest.tried_seeds(cfg.task), default=cfg.seed_start - 1) + 1
    window, last = None, None

    def show_in_window(command: TeleopCommand, ticks: int) -> None:
        window.overlay(key_map_columns(), episode_state_columns(
            seed, ticks / RECORD_FPS, env._max_episode_steps / RECORD_FPS, command, manifest.kept(cfg.task),
            cfg.episodes, last))
        window.show()

    try:
        if keys is None:
            env.reset(seed=seed)
            window = Window(env, cfg.view)
            keys, show = window.keys, show_in_window
        while manifest.kept(cfg.task) < cfg.episodes and (window is None or window.running):
            ending, success, actions, states = teleop_episode(env, seed, keys, show, gamepad)
            kept = ending != DROP and (success or cfg.keep_failures)
            if ending != DROP:
                entry = ManifestEntry(cfg.task, seed, success, len(actions))
                store_episode(cfg.out_dir, manifest, entry,
                              states.episode(env, seed, success, actions) if kept else None)
            last = outcome_line(seed, ending, success, kept, len(actions))
            yield last
            seed += 1
    finally:
        if window is not None:
            window.close()
        if gamepad is not None:
            gamepad.stop()
        env.close()
