"""A process that only simulates loads neither torch nor LeRobot.

Workers of `tavis record`, `tavis eval --expert` and LeRobot's async vector envs import the env, the demonstrators,
the episode log and the modules their jobs are unpickled from; none of them may pull in LeRobot (and torch with it).
"""

import json
import subprocess
import sys

WORKER = """
import json, sys
import lerobot_tavis.dataset_tools.record, lerobot_tavis.eval.protocol  # where worker jobs are unpickled from
from lerobot_tavis.eval.env_factory import make_tavis_env
from lerobot_tavis.experts.rollout import run_episode

env = make_tavis_env("wait_then_act", "gr1t2", "head_wrist", "id", (96, 128), 2.0, episode_log=sys.argv[1])
result = run_episode(env, seed=0)
env.close()
print(json.dumps({"image": env.observation_space["pixels"]["head"].shape, "steps": result.length_steps,
                  "loaded": [m for m in ("torch", "lerobot") if m in sys.modules]}))
"""


def test_a_simulating_worker_imports_neither_torch_nor_lerobot(tmp_path):
    log = tmp_path / "episodes.jsonl"
    out = subprocess.run([sys.executable, "-c", WORKER, str(log)], check=True, capture_output=True, text=True)
    report = json.loads(out.stdout.splitlines()[-1])
    assert report == {"image": [96, 128, 3], "steps": 40, "loaded": []}
    assert json.loads(log.read_text().splitlines()[-1])["seed"] == 0
