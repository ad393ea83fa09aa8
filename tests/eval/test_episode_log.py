"""The episode log: one line per genuine episode, with the final step's success conditions and GALT for successful
head-camera episodes."""

import json

import gymnasium as gym
import numpy as np

from lerobot_tavis import canonical
from lerobot_tavis.envs.vector import NEW_ROLLOUT_OPTION, FreezeAfterEpisodeEnd
from lerobot_tavis.eval.episode_log import EpisodeLogger
from lerobot_tavis.metrics.galt_metric import GALT
from lerobot_tavis.metrics.wrist_lead_metric import WRIST_LEAD
from tests.test_galt import episode, peek_then_grasp


class ScriptedEnv(gym.Env):
    """Replays a fixed action trajectory as the 'applied' actions and succeeds on its last step."""

    metadata = {"render_fps": 20}
    fps = 20
    observation_space = gym.spaces.Box(-1, 1, (1,))
    action_space = gym.spaces.Box(-np.inf, np.inf, (19,))

    def __init__(self, actions, success=True, camera_mode="head_only"):
        self.actions, self.success = actions, success
        self.robot_name, self.task, self.split, self.camera_mode = "gr1t2", "clutter_pick_lift", "id", camera_mode
        self.shadows = True
        self.task_description = "Lift the red soup can off the table."

    def reset(self, *, seed=None, options=None):
        self.t = 0
        return np.zeros(1, np.float32), {"is_success": False}

    def step(self, action):
        applied = self.actions[self.t]
        self.t += 1
        done = self.t == len(self.actions)
        success = done and self.success
        return np.zeros(1, np.float32), float(success), success, done and not success, {
            "is_success": success, "applied_action": applied,
            "conditions": {"target_lifted": done, "target_slow": success, "target_height_m": 1.0 + 0.01 * self.t},
            "reach": {"closest_hand_m": 0.3 / self.t, "target_moved_m": 0.01 * self.t}}


def _run(env, seed, steps):
    env.reset(seed=seed, options={NEW_ROLLOUT_OPTION: True})
    info = {}
    for _ in range(steps):
        *_, info = env.step(canonical.rest_action())
    return info


def test_a_successful_episode_is_logged_once_with_its_galt(tmp_path):
    actions = episode(20, 3.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0)
    log = tmp_path / "episodes.jsonl"
    env = FreezeAfterEpisodeEnd(EpisodeLogger(ScriptedEnv(actions), log, suite="tavis_head", task_id=3))
    info = _run(env, 1005, len(actions) + 5)  # extra steps hit the frozen terminal transition
    env.reset()  # an autoreset: replayed, not a new episode
    (record,) = [json.loads(line) for line in log.read_text().splitlines()]
    assert record["seed"] == 1005 and record["success"] and record["length_steps"] == len(actions)
    assert record["suite"] == "tavis_head" and record["task_id"] == 3 and record["task"] == "clutter_pick_lift"
    assert record["camera_mode"] == "head_only" and record["shadows"] is True
    assert record["conditions"] == {"target_lifted": True, "target_slow": True,
                                    "target_height_m": 1.0 + 0.01 * len(actions)}  # the final step's
    assert record["reach"] == {"closest_hand_m": 0.3 / len(actions), "target_moved_m": 0.01 * len(actions)}
    assert record["galt_reason"] == "ok" and abs(record["galt_s"] - 1.0) < 0.1 and record["galt_arm"] == "right"
    assert info["galt_s"] == record["galt_s"]


def test_no_galt_for_failures_or_fixed_camera_modes(tmp_path):
    actions = episode(20, 3.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0)
    log = tmp_path / "episodes.jsonl"
    for env in (EpisodeLogger(ScriptedEnv(actions, success=False), log, "tavis_head", 0),
                EpisodeLogger(ScriptedEnv(actions, camera_mode="fixed_only"), log, "tavis_head", 0)):
        _run(env, 7, len(actions))
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert len(records) == 2 and [r["success"] for r in records] == [False, True]
    assert records[0]["conditions"]["target_lifted"] and not records[0]["conditions"]["target_slow"]
    assert all(r[field] is None for r in records for field in GALT.fields + WRIST_LEAD.fields)


def test_hands_episodes_log_the_wrist_lead_of_the_final_grasp(tmp_path):
    actions = peek_then_grasp(20)
    log = tmp_path / "episodes.jsonl"
    _run(EpisodeLogger(ScriptedEnv(actions, camera_mode="fixed_wrist"), log, "tavis_hands", 0), 3, len(actions))
    (record,) = [json.loads(line) for line in log.read_text().splitlines()]
    assert record["wrist_lead_reason"] == "ok" and record["wrist_lead_arm"] == "right"
    assert abs(record["wrist_lead_s"] - 1.6) < 0.1
    assert record["galt_s"] is None  # fixed camera: no GALT


def test_the_log_writes_the_fields_of_every_metric_in_registry_order(tmp_path):
    actions = episode(20, 3.0, 1.0, hand=(1.4, 2.0), grasp_s=2.0)
    log = tmp_path / "episodes.jsonl"
    info = _run(EpisodeLogger(ScriptedEnv(actions), log, "tavis_head", 0), 0, len(actions))
    (record,) = [json.loads(line) for line in log.read_text().splitlines()]
    assert list(record) == ["robot", "suite", "task", "task_id", "split", "camera_mode", "shadows", "seed",
                            "success", "length_steps", "prompt", "conditions", "reach", *GALT.fields, *WRIST_LEAD.fields,
                            "instability"]
    assert all(info[field] == record[field] for field in GALT.fields + WRIST_LEAD.fields)
