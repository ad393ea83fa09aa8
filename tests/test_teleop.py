"""`tavis teleop`: the key mapping, and episodes recorded from scripted key presses that `tavis convert` reads."""

import json

import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.dataset_tools.convert import ConvertConfig, convert
from lerobot_tavis.teleop import (DROP, END, HAND_STEP_M, HEAD_STEP_RAD, KEY_BACKSPACE, KEY_DOWN, KEY_ENTER, KEY_LEFT,
                                  KEY_MAP, KEY_SPACE, KEY_TAB, TeleopCommand, TeleopConfig, episode_state_columns,
                                  key_map_columns, teleop)


def test_keys_move_the_active_hand_the_head_and_the_grippers():
    command = TeleopCommand()
    rest = canonical.rest_action()
    for key in "WWAQ":
        assert command.press(ord(key)) is None
    np.testing.assert_allclose(command.action[canonical.RIGHT.position] - rest[canonical.RIGHT.position],
                               [2 * HAND_STEP_M, HAND_STEP_M, HAND_STEP_M])
    command.press(KEY_TAB)
    command.press(ord("S"))
    command.press(KEY_SPACE)
    assert command.action[canonical.LEFT.position][0] == pytest.approx(rest[canonical.LEFT.position][0] - HAND_STEP_M)
    assert command.action[canonical.LEFT.gripper] == canonical.GRIPPER_CLOSED
    assert command.action[canonical.RIGHT.gripper] == canonical.GRIPPER_OPEN
    command.press(KEY_SPACE)
    assert command.action[canonical.LEFT.gripper] == canonical.GRIPPER_OPEN
    command.press(KEY_DOWN)
    command.press(KEY_LEFT)
    assert command.action[canonical.HEAD_PITCH] == pytest.approx(HEAD_STEP_RAD)  # down: +pitch
    assert command.action[canonical.HEAD_YAW] == pytest.approx(HEAD_STEP_RAD)  # left: +yaw
    before = command.action.copy()
    assert command.press(ord("Z")) is None
    np.testing.assert_array_equal(command.action, before)  # unbound keys change nothing
    command.press(ord("0"))
    np.testing.assert_array_equal(command.action, rest)
    assert (command.press(KEY_ENTER), command.press(KEY_BACKSPACE)) == (END, DROP)


def scripted(presses: dict[int, list[int]]):
    """A key source: the presses listed for each tick (ticks counted across episodes)."""
    tick = {"n": 0}

    def keys():
        tick["n"] += 1
        return presses.get(tick["n"] - 1, [])
    return keys


def unseen(command, ticks):
    """A `show` that draws nothing."""


def test_recorded_episodes_are_raw_episodes_that_convert_reads(tmp_path):
    # Episode 1 (seed 200000): dropped at tick 5. Episode 2 (seed 200001): the right hand moves forward and up
    # and the head looks down for 60 ticks, then ENTER ends it: a failure, kept with keep_failures.
    presses = {5: [KEY_BACKSPACE]}
    presses.update({6 + t: [ord("W"), ord("Q"), KEY_DOWN] for t in range(0, 30, 3)})
    presses[6 + 60] = [KEY_ENTER]
    cfg = TeleopConfig(out_dir=tmp_path / "raw", task="conditional_pick", episodes=1, keep_failures=True)
    outcomes = list(teleop(cfg, keys=scripted(presses), show=unseen))
    assert outcomes == ["seed 200000: dropped", "seed 200001: failure, kept (60 steps)"]

    manifest = json.loads((tmp_path / "raw" / "manifest.json").read_text())
    (entry,) = manifest["episodes"]
    assert (manifest["fps"], entry["seed"], entry["n_steps"], entry["success"]) == (60, 200001, 60, False)

    root = convert(ConvertConfig(tmp_path / "raw", "local/human", tmp_path / "dataset", image_size=(24, 32),
                                 cameras=("head",)), progress=False)
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    actions = np.stack(LeRobotDataset("local/human", root=root, video_backend="pyav").hf_dataset["action"])
    rest = canonical.rest_action()
    assert len(actions) == 20  # 60 ticks at 60 Hz -> 20 frames at 20 Hz
    reach = actions[-1][canonical.RIGHT.position] - rest[canonical.RIGHT.position]
    np.testing.assert_allclose(reach, [10 * HAND_STEP_M, 0, 10 * HAND_STEP_M], atol=1e-6)
    assert actions[-1][canonical.HEAD_PITCH] == pytest.approx(10 * HEAD_STEP_RAD, abs=1e-6)


def test_a_rerun_continues_with_the_next_seed(tmp_path):
    cfg = TeleopConfig(out_dir=tmp_path / "raw", task="conditional_pick", episodes=1, keep_failures=True)
    list(teleop(cfg, keys=scripted({3: [KEY_ENTER]}), show=unseen))
    more = TeleopConfig(out_dir=tmp_path / "raw", task="conditional_pick", episodes=2, keep_failures=True)
    assert list(teleop(more, keys=scripted({3: [KEY_ENTER]}), show=unseen)) == [
        "seed 200001: failure, kept (3 steps)"]


def test_without_a_display_it_says_how_to_get_one(tmp_path, monkeypatch):
    from lerobot_tavis.viewer import NoDisplayError

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(NoDisplayError, match="xvfb-run -a tavis teleop"):
        list(teleop(TeleopConfig(out_dir=tmp_path / "raw", task="conditional_pick")))
    assert not (tmp_path / "raw").exists()


class ScriptedGamepad:
    """A LeRobot InputController whose readings come from a script: (deltas, gripper command, end status) per tick."""

    def __init__(self, ticks):
        self.ticks, self.reading, self.stopped = list(ticks), None, False

    def update(self):
        self.reading = self.ticks.pop(0) if self.ticks else ((0.0, 0.0, 0.0), "stay", None)

    def get_deltas(self):
        return self.reading[0]

    def gripper_command(self):
        return self.reading[1]

    def get_episode_end_status(self):
        return self.reading[2]

    def stop(self):
        self.stopped = True


def test_a_gamepad_moves_the_active_hand_closes_its_gripper_and_ends_the_episode(tmp_path):
    from lerobot.teleoperators.utils import TeleopEvents

    ticks = [((0.001, 0.0, 0.002), "stay", None)] * 30 + [((0.0, 0.0, 0.0), "close", None)] * 5
    ticks += [((0.0, 0.0, 0.0), "stay", TeleopEvents.FAILURE)]
    gamepad = ScriptedGamepad(ticks)
    cfg = TeleopConfig(out_dir=tmp_path / "raw", task="conditional_pick", episodes=1, keep_failures=True)
    assert list(teleop(cfg, keys=scripted({0: [KEY_TAB]}), show=unseen, gamepad=gamepad)) == [
        "seed 200000: failure, kept (35 steps)"]
    assert gamepad.stopped
    from lerobot_tavis.dataset_tools.raw import load_episode

    episode = load_episode(tmp_path / "raw" / "conditional_pick" / "seed_00200000.npz")
    rest = canonical.rest_action()
    moved = episode.actions[-1][canonical.LEFT.position] - rest[canonical.LEFT.position]  # TAB: the left hand
    np.testing.assert_allclose(moved, [0.030, 0.0, 0.060], atol=1e-9)
    assert episode.actions[-1][canonical.LEFT.gripper] == canonical.GRIPPER_CLOSED
    np.testing.assert_array_equal(episode.actions[-1][canonical.RIGHT.position], rest[canonical.RIGHT.position])


def test_a_failed_episode_not_kept_says_so_as_it_ends_and_on_screen(tmp_path):
    """Without --keep-failures an episode ended by ENTER is discarded: its line says so (and how to keep it) the
    moment it ends, and the window's state shows it during the next episode."""
    cfg = TeleopConfig(out_dir=tmp_path / "raw", task="conditional_pick", episodes=1)
    shown = []
    outcomes = teleop(cfg, keys=scripted({3: [KEY_ENTER], 8: [KEY_TAB]}),
                      show=lambda command, ticks: shown.append(episode_state_columns(
                          0, ticks / 60, 20.0, command, 0, 1, None)[1]))
    first = next(outcomes)
    assert first == "seed 200000: failure, not kept (3 steps; --keep-failures keeps failed episodes)"
    assert len(shown) == 4  # the start and three ticks: the line came as the episode ended, not at the end
    outcomes.close()  # stops the session: the window (here none) and the env close
    manifest = json.loads((tmp_path / "raw" / "manifest.json").read_text())
    assert manifest["episodes"] == [] and [entry["seed"] for entry in manifest["discarded"]] == [200000]
    assert shown[0].splitlines()[1:3] == [" 0.0 / 20 s", "right, gripper open"]


def test_the_window_shows_the_key_map_and_the_episode_state():
    keys, does = key_map_columns()
    assert keys.splitlines()[0] == "W / S" and "ENTER" in keys and "BACKSPACE" in keys
    assert len(keys.splitlines()) == len(does.splitlines()) == len(KEY_MAP)
    command = TeleopCommand()
    command.press(KEY_TAB)
    command.press(KEY_SPACE)
    labels, values = episode_state_columns(200001, 3.25, 20.0, command, 1, 2, "seed 200000: success, kept (90 steps)")
    assert dict(zip(labels.splitlines(), values.splitlines())) == {
        "seed": "200001", "time": " 3.2 / 20 s", "hand": "left, gripper closed", "kept": "1 of 2",
        "last": "seed 200000: success, kept (90 steps)"}
