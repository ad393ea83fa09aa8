"""benchmarks/reach_sides.py: which object the hands went to, counted over the episodes that reached one."""

import json
import sys


def _episode(seed, target_m, other_m):
    return {"robot": "gr1t2", "suite": "tavis_head", "task": "conditional_pick", "task_id": 0, "split": "id",
            "camera_mode": "head_wrist", "seed": seed, "success": False,
            "reach": {"closest_hand_m": target_m, "closest_hand_other_m": other_m}}


def test_counts_wrong_sides_among_the_episodes_that_came_near_an_object(benchmark_script, tmp_path, monkeypatch,
                                                                        capsys):
    script = benchmark_script("reach_sides")
    episodes = [_episode(1000, 0.01, 0.30),  # reached the target
                _episode(1001, 0.25, 0.04),  # reached the other object
                _episode(1002, 0.09, 0.08),  # between them, nearer the other
                _episode(1003, 0.27, 0.26),  # stood still: left out
                _episode(1004, 0.05, None)]  # logged without the other object: left out
    cell = tmp_path / "eval" / "tavis_head__id"
    cell.mkdir(parents=True)
    (cell / "episodes.jsonl").write_text("".join(json.dumps(e) + "\n" for e in episodes))
    assert script.count_sides(episodes) == (3, 2)
    monkeypatch.setattr(sys, "argv", ["reach_sides.py", str(tmp_path / "eval")])
    script.main()
    assert capsys.readouterr().out.strip() == (
        f"{tmp_path / 'eval'}: 5 episodes; closest hand to the target 9.0 cm at the median, 2 within 5 cm; 3 with a "
        "hand within 10 cm of an object, 2 of them nearer another object than the target")
