"""Actions and simulations that would go wrong: huge values, far targets, an unstable simulation. Every finite
action is usable; an instability ends the episode with its reason in info, the episode log and the report."""

import json

import numpy as np
import pytest

from lerobot_tavis import canonical
from lerobot_tavis.envs.control import MAX_TARGET_DISTANCE_M
from lerobot_tavis.eval.episode_log import EpisodeLogger
from lerobot_tavis.eval.report import build_report, markdown
from tests.conftest import run_steps
from tests.eval.test_report import _eval_dir


def test_an_unstable_simulation_ends_the_episode_with_the_reason(small_env, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warnings to MUJOCO_LOG.TXT in the working directory
    env = small_env(task="conditional_pick", robot="gr1t2", camera_mode="fixed_only", image_size=(16, 16))
    env.reset(seed=0)
    _, _, _, truncated, info = env.step(canonical.rest_action())
    assert not truncated and "instability" not in info
    env.unwrapped._sim.data.qvel[:] = 1e12  # a body at 1e12 m/s: MuJoCo warns and resets its state
    _, reward, terminated, truncated, info = env.step(canonical.rest_action())
    assert truncated and not terminated and reward == 0.0 and not info["is_success"]
    assert info["instability"] == "mjWARN_BADQVEL at step 2 (0.10 s)"
    env.reset(seed=0)  # a new episode starts clean
    assert "instability" not in env.step(canonical.rest_action())[4]


@pytest.mark.parametrize("distance_m", [1e4, 1e200])
def test_a_target_at_any_finite_distance_gives_the_closest_pose_in_its_direction(small_env, distance_m):
    direction = np.array([3.0, 2.0, 1.5]) / np.linalg.norm([3.0, 2.0, 1.5])
    reached = {}
    for distance in (MAX_TARGET_DISTANCE_M, distance_m):
        env = small_env(task="tabletop", robot="gr1t2", camera_mode="fixed_only")
        env.reset(seed=0)
        action = canonical.rest_action()
        action[canonical.LEFT.position] = direction * distance
        reached[distance] = run_steps(env, action, 40)["agent_pos"][canonical.LEFT.position]
    rest = canonical.rest_action()[canonical.LEFT.position]
    assert np.linalg.norm(reached[distance_m] - rest) > 0.1  # the hand stretched toward the far target
    np.testing.assert_allclose(reached[distance_m], reached[MAX_TARGET_DISTANCE_M], atol=1e-6)


def test_a_huge_quaternion_is_normalised_not_turned_into_nan(small_env):
    env = small_env(task="tabletop", robot="gr1t2", camera_mode="fixed_only")
    env.reset(seed=0)
    action = canonical.rest_action()
    action[canonical.LEFT.quaternion] *= 1e200
    applied = env.step(action)[4]["applied_action"]
    np.testing.assert_allclose(applied[canonical.LEFT.quaternion], canonical.rest_action()[canonical.LEFT.quaternion])
    assert np.all(np.isfinite(applied))


def test_an_episode_ended_by_an_instability_logs_the_warning(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warnings to MUJOCO_LOG.TXT in the working directory
    from lerobot_tavis.envs.env import TavisEnv

    log = tmp_path / "episodes.jsonl"
    env = EpisodeLogger(TavisEnv("conditional_pick", camera_mode="fixed_only", image_size=(16, 16), cameras=()),
                        log, "tavis_head", 0)
    env.reset(seed=3)
    env.step(canonical.rest_action())
    env.unwrapped._sim.data.qvel[:] = 1e12
    env.step(canonical.rest_action())
    (record,) = [json.loads(line) for line in log.read_text().splitlines()]
    assert not record["success"] and record["instability"].startswith("mjWARN_BADQVEL at step 2")
    assert record["conditions"] is None  # the state was reset: nothing to evaluate
    env.close()


def test_the_report_counts_episodes_ended_by_an_instability(tmp_path):
    _eval_dir(tmp_path / "id", "id", {"conditional_pick": [True, False, False]}, extra=0)
    log = tmp_path / "id" / "episodes.jsonl"
    records = [json.loads(line) for line in log.read_text().splitlines()]
    records[0]["instability"] = "mjWARN_BADQACC at step 7 (0.35 s)"  # seed 1002, a failure
    log.write_text("".join(json.dumps(r) + "\n" for r in records))
    report = build_report(tmp_path)
    assert report["cells"][0]["unstable"] == 1
    assert "simulator instability (counted as failures" in markdown(report) and "conditional_pick id: 1 of 3" in \
        markdown(report)
