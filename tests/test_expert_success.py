"""benchmarks/expert_success.py --results: a rerun plays only the chunks not kept yet and writes the whole table."""

import json
import sys


def test_a_rerun_plays_only_the_missing_chunk_and_writes_the_table(benchmark_script, tmp_path, monkeypatch):
    script = benchmark_script("expert_success")
    played = []

    def run_chunk(job):  # stands in for the demonstrator: 1 success in every chunk, lead 1.0 s
        played.append(job)
        task, robot, split, seeds = job
        return task, robot, split, seeds, 1, [1.0]

    monkeypatch.setattr(script, "run_chunk", run_chunk)
    results, table = tmp_path / "chunks", tmp_path / "table.md"
    results.mkdir()
    (results / "conditional_pick-gr1t2-id-0-2.json").write_text(json.dumps([2, [0.5, None]]))  # kept from before
    monkeypatch.setattr(sys, "argv", ["expert_success.py", "--episodes", "4", "--chunk", "2", "--robots", "gr1t2",
                                      "--tasks", "conditional_pick", "--splits", "id", "--workers", "1",
                                      "--results", str(results), "--out", str(table)])
    script.main()
    assert [job[3] for job in played] == [range(2, 4)]
    assert json.loads((results / "conditional_pick-gr1t2-id-2-4.json").read_text()) == [1, [1.0]]
    assert "| conditional_pick | gr1t2 | 75.0% " in table.read_text()
    assert "(3/4)" in table.read_text() and table.read_text().startswith("| task | robot |")
    played.clear()
    script.main()  # everything kept: nothing plays, same table
    assert played == [] and "(3/4)" in table.read_text()
