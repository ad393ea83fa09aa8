"""Re-runs, resumes and concurrent runs on one output never mix, skip or lose results.

A resumed or re-run `tavis eval` with other settings is refused in one line naming the difference (`--restart`
plays the cell again), every episode record carries its run's identity and `tavis report` refuses a cell whose
records come from different runs; a second run into an output directory in use is refused naming the first, and a
run killed with -9 leaves no stale lock; `tavis convert` never writes where it reads."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest

from lerobot_tavis.errors import InputError
from lerobot_tavis.eval.report import build_report
from lerobot_tavis.locking import exclusive_output, lock_path

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

EVAL = ["eval", "--tasks", "peeking_box", "--splits", "id", "--episode-length-s", "1",
        "--film-episodes", "0"]
CELL = "tavis_hands__id"


def _command(*args) -> list[str]:
    return [sys.executable, "-m", "lerobot_tavis.cli", *map(str, args)]


def _argv(*args) -> list[str]:
    """`tavis` arguments for `main` in this process (the `refused` fixture): where a test reads a refusal's line,
    not the process."""
    return list(map(str, args))


def _tavis(*args) -> subprocess.CompletedProcess:
    return subprocess.run(_command(*args), capture_output=True, text=True, env={**os.environ, "MUJOCO_GL": "egl"},
                          timeout=600)


def _start(*args) -> subprocess.Popen:
    return subprocess.Popen(_command(*args), env={**os.environ, "MUJOCO_GL": "egl"}, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def _error_line(done: subprocess.CompletedProcess) -> str:
    """The one line a refused command printed (exit status 1)."""
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 1 and len(lines) == 1, done.stderr
    return lines[0]


def _wait_for(condition, process: subprocess.Popen, what: str) -> None:
    deadline = time.monotonic() + 300
    while not condition():
        assert process.poll() is None and time.monotonic() < deadline, f"{what} never happened"
        time.sleep(0.05)


def _records(out):
    return [json.loads(line) for line in (out / CELL / "episodes.jsonl").read_text().splitlines()]


@pytest.fixture(scope="module")
def finished_eval(tmp_path_factory):
    """A finished `tavis eval --expert` output: one peeking_box episode of 1 s (gr1t2, head_wrist, seed 1000)."""
    out = tmp_path_factory.mktemp("runs") / "eval"
    done = _tavis(*EVAL, "--expert", "--episodes", "1", "--out", out)
    assert done.returncode == 0, done.stderr
    return out


def test_a_killed_eval_resumed_with_other_settings_is_refused_and_the_same_settings_resume(tmp_path, refused):
    out = tmp_path / "eval"
    first = _start(*EVAL, "--expert", "--episodes", "20", "--chunk-episodes", "1", "--out", out)
    try:
        _wait_for(lambda: any(out.glob(f".{CELL}.chunks/*.done.json")), first, "a finished chunk")
    finally:
        first.kill()
        first.wait()
    assert not (out / CELL).exists()  # killed before the cell was complete
    checkpoint = tmp_path / "pretrained_model"
    checkpoint.mkdir()
    (checkpoint / "config.json").write_text("{}")
    for other, shown in ((["--expert", "--robot", "reachy2"], "--robot gr1t2, not --robot reachy2"),
                         (["--expert", "--camera-mode", "fixed_wrist"], "--camera-mode head_wrist, not --camera-mode "
                                                                        "fixed_wrist"),
                         (["--policy", checkpoint], f"--expert, not --policy {checkpoint}")):
        line = refused(_argv(*EVAL, *other, "--episodes", "20", "--chunk-episodes", "1", "--out", out))
        assert line == (f"tavis eval: error: {out}/.{CELL}.chunks was played with {shown}: pass --restart to play it "
                        "again with these settings, or give another --out")
    done = _tavis(*EVAL, "--expert", "--episodes", "20", "--chunk-episodes", "1", "--out", out)
    assert done.returncode == 0, done.stderr
    records = _records(out)
    assert sorted(r["seed"] for r in records) == list(range(1000, 1020))
    assert {(r["robot"], r["camera_mode"], r["run"]["robot"], r["run"]["policy"]) for r in records} == {
        ("gr1t2", "head_wrist", "gr1t2", "scripted demonstrators")}
    info = json.loads((out / CELL / "eval_info.json").read_text())
    assert all(r["run"] == info["run"] for r in records)


def test_a_finished_eval_rerun_with_other_settings_is_refused_and_restart_plays_it_again(finished_eval, tmp_path,
                                                                                          refused):
    out = shutil.copytree(finished_eval, tmp_path / "eval")
    for other, shown in ((["--episodes", "2"], "--episodes 1, not --episodes 2"),
                         (["--seed", "7"], "--seed 1000, not --seed 7"),
                         (["--robot", "reachy2"], "--robot gr1t2, not --robot reachy2"),
                         (["--camera-mode", "fixed_wrist"], "--camera-mode head_wrist, not --camera-mode fixed_wrist"),
                         (["--episode-length-s", "2"], "--episode-length-s 1, not --episode-length-s 2")):
        line = refused(_argv(*EVAL, "--expert", "--episodes", "1", *other, "--out", out))
        assert line == (f"tavis eval: error: {out}/{CELL} was played with {shown}: pass --restart to play it again "
                        "with these settings, or give another --out")
    line = refused(_argv(*EVAL, "--expert", "--episodes", "1", "--robot", "reachy2", "--splits", "ood_spatial",
                         "--out", out))  # another cell into an output of another run's cells
    assert line == (f"tavis eval: error: {out} holds {CELL}, which was played with --robot gr1t2, not --robot "
                    "reachy2: one output directory holds the cells of one run; give another --out")
    same = _tavis(*EVAL, "--expert", "--episodes", "1", "--out", out)
    assert same.returncode == 0 and f"{CELL}: done already, skipped" in same.stdout
    again = _tavis(*EVAL, "--expert", "--episodes", "2", "--restart", "--out", out)
    assert again.returncode == 0, again.stderr
    assert f"{CELL}: played with other settings, playing it again (--restart)" in again.stdout
    assert [(r["seed"], r["run"]["episodes"]) for r in _records(out)] == [(1000, 2), (1001, 2)]


def _rewrite_records(cell, change) -> None:
    log = cell / "episodes.jsonl"
    log.write_text("".join(json.dumps(change(json.loads(line))) + "\n" for line in log.read_text().splitlines()))


def test_report_refuses_a_cell_whose_records_come_from_different_runs(finished_eval, tmp_path, refused):
    out = shutil.copytree(finished_eval, tmp_path / "eval")
    (record,) = _records(out)
    other = {**record, "seed": 1001, "run": {**record["run"], "policy": "/elsewhere/pretrained_model",
                                             "policy_sha256": "0" * 64}}
    with open(out / CELL / "episodes.jsonl", "a") as log:  # what a resume with another --policy appended before
        log.write(json.dumps(other) + "\n")
    info = json.loads((out / CELL / "eval_info.json").read_text())
    info["per_task"][0]["metrics"]["successes"].append(False)
    (out / CELL / "eval_info.json").write_text(json.dumps(info))
    line = refused(_argv("report", out))
    assert line == (f'tavis report: error: peeking_box id: its episodes disagree on run.policy ("scripted '
                    f'demonstrators" and "/elsewhere/pretrained_model", in {out}/{CELL}): they come from different runs')


def test_report_reads_records_from_before_run_identities_and_pools_runs_of_other_seeds(finished_eval, tmp_path):
    old = shutil.copytree(finished_eval, tmp_path / "old" / "eval")
    _rewrite_records(old / CELL, lambda record: {k: v for k, v in record.items() if k != "run"})
    info = json.loads((old / CELL / "eval_info.json").read_text())
    (old / CELL / "eval_info.json").write_text(json.dumps({k: v for k, v in info.items() if k != "run"}))
    (cell,) = build_report(old)["cells"]
    assert cell["n"] == 1  # reported as before
    shutil.copytree(old, tmp_path / "old" / "fixed")
    _rewrite_records(tmp_path / "old" / "fixed" / CELL, lambda record: {**record, "camera_mode": "fixed_wrist"})
    with pytest.raises(InputError, match="peeking_box id: its episodes disagree on camera_mode"):
        build_report(tmp_path / "old")
    later = shutil.copytree(finished_eval, tmp_path / "new" / "later")  # the same run with the next seed
    _rewrite_records(later / CELL, lambda record: {**record, "seed": 1001, "run": {**record["run"], "seed": 1001}})
    shutil.copytree(finished_eval, tmp_path / "new" / "first")
    (cell,) = build_report(tmp_path / "new")["cells"]
    assert cell["n"] == 2
    shutil.copytree(old, tmp_path / "new" / "old")
    with pytest.raises(InputError, match="peeking_box id: its episodes disagree on run "):
        build_report(tmp_path / "new")


def _record_command(tmp_path, request):
    return ["record", "--robot", "gr1t2", "--tasks", "conditional_pick", "--episodes-per-task", "1", "--out",
            tmp_path / "out"]


def _convert_command(tmp_path, request):
    return ["convert", request.getfixturevalue("raw_copy"), "--repo-id", "local/x", "--root", tmp_path / "out",
            "--image-size", "24x32", "--cameras", "head", "--storage", "png", "--overwrite"]


def _eval_command(tmp_path, request):
    return [*EVAL, "--expert", "--episodes", "1", "--out", tmp_path / "out"]


@pytest.mark.parametrize("name,command", [("record", _record_command), ("convert", _convert_command),
                                          ("eval", _eval_command)])
def test_a_second_run_into_an_output_in_use_is_refused_and_kill_9_leaves_no_stale_lock(tmp_path, request, name,
                                                                                      command):
    args = command(tmp_path, request)
    lock = lock_path(tmp_path / "out")
    first = _start(*args)
    try:
        _wait_for(lambda: lock.exists() and f"pid {first.pid} " in lock.read_text(), first, "the first run's lock")
        first.send_signal(signal.SIGSTOP)  # holds the lock as long as the test needs
        line = _error_line(_tavis(*args))
        assert line.startswith(f"tavis {name}: error: {tmp_path / 'out'} is in use by pid {first.pid} (tavis {name} ")
        assert line.endswith(": wait for it to end, or give another output directory")
    finally:
        first.kill()
        first.wait()
    with exclusive_output(tmp_path / "out"):  # the kernel released the lock of the killed run
        assert f"pid {os.getpid()} " in lock.read_text()
    assert not lock.exists()  # removed by the run that ends


def _files(folder) -> dict:
    return {path.relative_to(folder): path.read_bytes() for path in folder.rglob("*") if path.is_file()}


@pytest.mark.parametrize("where", ["same", "above", "inside", "link", "from_tavis"])
def test_convert_refuses_a_root_that_is_holds_or_lies_in_its_input(raw_copy, tmp_path, refused, where):
    before = _files(raw_copy)
    if where == "link":
        (tmp_path / "link").symlink_to(raw_copy)
    root = {"same": raw_copy, "above": tmp_path, "inside": raw_copy / "dataset", "link": tmp_path / "link",
            "from_tavis": raw_copy}[where]
    source = ["--from-tavis", raw_copy] if where == "from_tavis" else [raw_copy]
    line = refused(_argv("convert", *source, "--repo-id", "local/x", "--root", root, "--overwrite"))
    relation = {"above": "holds", "inside": "is inside"}.get(where, "is")
    assert line == (f"tavis convert: error: --root {root} {relation} the input {raw_copy}: a conversion never writes "
                    "where it reads; give a destination outside it")
    assert _files(raw_copy) == before
    assert not list(tmp_path.glob(".*partial*"))
