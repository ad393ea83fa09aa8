"""benchmarks/paired_success.py: episodes paired by (task, split, seed) and the exact McNemar test."""

import json
import sys

import pytest


def _log(folder, successes, first_seed=1000):
    cell = folder / "tavis_head__id"
    cell.mkdir(parents=True)
    (cell / "episodes.jsonl").write_text("".join(
        json.dumps({"task": "conditional_pick", "split": "id", "seed": first_seed + i, "success": s}) + "\n"
        for i, s in enumerate(successes)))


def test_pairs_by_seed_and_tests_the_discordant_episodes(benchmark_script, tmp_path, monkeypatch, capsys):
    script = benchmark_script("paired_success")
    _log(tmp_path / "a", [True, True, True, False, False])
    _log(tmp_path / "b", [True, False, False, True, False, True], first_seed=1000)  # seed 1005: unpaired
    monkeypatch.setattr(sys, "argv", ["paired_success.py", str(tmp_path / "a"), str(tmp_path / "b")])
    script.main()
    assert capsys.readouterr().out.startswith("5 paired episodes: A 3 successes, B 2; both 1, only A 2, only B 1;")
    assert script.mcnemar_exact_p(0, 0) == 1.0
    assert script.mcnemar_exact_p(11, 17) == pytest.approx(0.345, abs=1e-3)  # 2 * P(X <= 11), X ~ B(28, 1/2)
    assert script.mcnemar_exact_p(0, 6) == pytest.approx(2 / 64)
