"""The baselines table's index, docs/results/baselines.json, damaged or lying: `tavis table` and `tavis ablation` exit
with one line naming the file, the entry and the field; `tavis table-add` refuses an entry its results.json
contradicts and leaves the file as it was."""

import json
import shutil

import pytest

ENTRY = {"robot": "gr1t2", "task": "conditional_pick", "camera_mode": "head_wrist",
         "policy": "act_hand_relative_head_wrist_compact", "training_seed": 1000, "results": "cell/results.json"}


@pytest.fixture
def repository(eval_root, tmp_path):
    """A repository root holding one expert evaluation of conditional_pick (gr1t2, head_wrist) as `cell/` and a
    baselines.json naming it."""
    shutil.copytree(eval_root / "step_100", tmp_path / "cell")
    (tmp_path / "baselines.json").write_text(json.dumps([ENTRY]))
    return tmp_path


def _table(refused, root, command="table"):
    extra = ["--robot", "gr1t2"] if command == "ablation" else []
    return refused([command, *extra, "--baselines", str(root / "baselines.json"), "--root", str(root)])


@pytest.mark.parametrize(("damage", "problem"), [
    (lambda path: path.write_text(path.read_text()[:40]), "baselines.json: not a JSON file (Unterminated string"),
    (lambda path: path.write_text(json.dumps(ENTRY)), "baselines.json: must be a list of entries, got dict"),
    (lambda path: path.write_text(json.dumps([{**ENTRY, "training_seed": "1000"}])),
     "baselines.json: entry 0: training_seed must be an integer, got '1000'"),
    (lambda path: path.write_text(json.dumps([{k: v for k, v in ENTRY.items() if k != "policy"}])),
     "baselines.json: entry 0: must have exactly the fields robot, task, camera_mode, policy, training_seed, "
     "results; missing policy"),
    (lambda path: path.write_text(json.dumps([ENTRY, ENTRY])),
     "baselines.json: entry 1: gr1t2 conditional_pick head_wrist is entry 0 already"),
    (lambda path: path.write_text(json.dumps([{**ENTRY, "camera_mode": "fixed_wrist"}])),
     "baselines.json: entry 0: cell/results.json was played with camera_modes ['head_wrist'], the entry says "
     "'fixed_wrist'"),
    (lambda path: path.write_text(json.dumps([{**ENTRY, "task": "peeking_box"}])),
     "baselines.json: entry 0: cell/results.json holds no id cell of peeking_box"),
    (lambda path: (path.parent / "cell" / "results.json").unlink(),
     "baselines.json: entry 0: results cell/results.json is not a file under"),
    (lambda path: (path.parent / "cell" / "results.json").write_text("[]"),
     "baselines.json: entry 0: cell/results.json is not a `tavis eval` / `tavis report` results.json"),
])
@pytest.mark.parametrize("command", ["table", "ablation"])
def test_a_damaged_or_lying_baselines_file_is_one_line(repository, refused, damage, problem, command):
    damage(repository / "baselines.json")
    message = _table(refused, repository, command)
    assert message.startswith(f"tavis {command}: error: {repository / 'baselines.json'}"), message
    assert problem in message


def test_table_add_refuses_an_entry_its_results_contradict_and_leaves_the_file(repository, refused):
    before = (repository / "baselines.json").read_bytes()
    message = refused(["table-add", "--robot", "reachy2", "--task", "conditional_pick", "--camera-mode", "head_wrist",
                       "--policy", "p", "--training-seed", "1", "--results", "cell/results.json",
                       "--baselines", str(repository / "baselines.json"), "--root", str(repository)])
    assert message == ("tavis table-add: error: the new entry: cell/results.json was played with robots ['gr1t2'], "
                       "the entry says 'reachy2'")
    assert (repository / "baselines.json").read_bytes() == before
    assert sorted(path.name for path in repository.iterdir()) == ["baselines.json", "cell"]
