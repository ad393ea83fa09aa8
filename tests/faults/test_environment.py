"""The surroundings refuse: a read-only folder, a full disk, a file where a folder should be, a name too long, a
path that is not UTF-8, Ctrl-C. Each is one line `tavis <command>: error: ...` (exit status 1; 130 for Ctrl-C),
and nothing half-written is left to be counted by a later run. Temporary files of killed runs do not pile up in
the system's temporary directory."""

import ctypes
import errno
import glob
import json
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lerobot_tavis.atomic import NAME_MAX_BYTES, write_text
from lerobot_tavis.errors import PathExistsError
from lerobot_tavis.eval.report import build_report
from lerobot_tavis.staging import staged_directory
from tests.eval.test_report import _eval_dir

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

EXPERT_EVAL = ["eval", "--expert", "--tasks", "conditional_pick", "--splits", "id", "--episode-length-s", "0.5"]
_PR_CAPBSET_DROP = 24  # from <linux/prctl.h>
_ROOT_OVERRIDES = (1, 2, 3)  # CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, CAP_FOWNER


def _tavis(args, *, tmpdir, preexec_fn=None, timeout=300) -> subprocess.CompletedProcess:
    """`tavis ARGS` in a process of its own, its temporary files in `tmpdir`."""
    env = {**os.environ, "MUJOCO_GL": "egl", "TMPDIR": str(tmpdir)}
    return subprocess.run([sys.executable, "-m", "lerobot_tavis.cli", *args], capture_output=True, env=env,
                          preexec_fn=preexec_fn, timeout=timeout)


def _one_line(result: subprocess.CompletedProcess, status: int = 1) -> str:
    """The single line a refused command printed on stderr (progress bars aside)."""
    lines = [line for line in result.stderr.decode().replace("\r", "\n").splitlines()
             if line.strip() and "%|" not in line]
    assert result.returncode == status and len(lines) == 1, result.stderr.decode()
    return lines[0]


def _as_a_user():
    """preexec_fn: as root, give up the capabilities that let root write where permissions forbid it (dropped from
    the bounding set, so the program run next lacks them), so that a read-only folder is read-only."""
    if os.geteuid() == 0:
        libc = ctypes.CDLL(None, use_errno=True)
        for capability in _ROOT_OVERRIDES:
            if libc.prctl(_PR_CAPBSET_DROP, capability, 0, 0, 0) != 0:
                raise OSError(ctypes.get_errno(), "prctl(PR_CAPBSET_DROP)")


def _file_size_limit(max_bytes: int):
    """preexec_fn: the kernel refuses every write past `max_bytes` in a file (EFBIG), as a full disk refuses
    writes (ENOSPC), in this process and every one it starts; Python ignores SIGXFSZ, so the write fails."""
    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (max_bytes, max_bytes))


def _hidden(path: Path) -> list[str]:
    """Everything under `path` in a hidden folder or hidden itself: staging copies, partial files, chunks."""
    return sorted(str(p.relative_to(path)) for p in path.rglob("*")
                  if any(part.startswith(".") for part in p.relative_to(path).parts))


@pytest.fixture
def tmpdir_(tmp_path):
    """The system temporary directory the commands see, empty."""
    path = tmp_path / "system-tmp"
    path.mkdir()
    return path


def test_a_read_only_folder_is_one_line_and_nothing_is_written(tmp_path, tmpdir_, raw_copy):
    folder = tmp_path / "read-only"
    folder.mkdir()
    folder.chmod(0o555)
    result = _tavis([*EXPERT_EVAL, "--out", str(folder / "out")], tmpdir=tmpdir_, preexec_fn=_as_a_user)
    assert _one_line(result) == f"tavis eval: error: {folder / 'out'}: Permission denied"
    result = _tavis(["convert", str(raw_copy), "--repo-id", "local/x", "--root", str(folder / "dataset"),
                     "--image-size", "48x64"], tmpdir=tmpdir_, preexec_fn=_as_a_user)
    assert _one_line(result) == f"tavis convert: error: {folder / 'dataset'}: Permission denied"
    assert list(folder.iterdir()) == [] and list(tmpdir_.iterdir()) == []


def test_a_full_disk_is_one_line_and_the_next_run_counts_only_whole_results(tmp_path, tmpdir_):
    out = tmp_path / "out"
    args = [*EXPERT_EVAL, "--episodes", "2", "--chunk-episodes", "1", "--out", str(out)]
    # Room for one episode's log line (about 850 bytes), not for the cell's log of two.
    result = _tavis(args, tmpdir=tmpdir_, preexec_fn=_file_size_limit(1200))
    assert _one_line(result) == f"tavis eval: error: {os.strerror(errno.EFBIG)} (while writing)"
    assert not (out / "tavis_head__id").exists() and not (out / "results.json").exists()
    chunks = [f".tavis_head__id.chunks/00_conditional_pick_000{seed}.{kind}"
              for seed in (1000, 1001) for kind in ("done.json", "jsonl")]
    assert _hidden(out) == [".tavis_head__id.chunks", *chunks, ".tavis_head__id.chunks/run.json"]
    assert _tavis(args, tmpdir=tmpdir_).returncode == 0  # the finished chunks are used, the cell written whole
    (cell,) = json.loads((out / "results.json").read_text())["cells"]
    assert cell["n"] == 2 and _hidden(out) == [] and list(tmpdir_.iterdir()) == []


def test_no_space_left_while_a_report_is_written(tmp_path, tmpdir_):
    _eval_dir(tmp_path / "tavis_head__id", "id", {"conditional_pick": [True, False]})
    (tmp_path / ".results.json.partial").symlink_to("/dev/full")  # its writes fail with ENOSPC
    result = _tavis(["report", str(tmp_path)], tmpdir=tmpdir_)
    assert _one_line(result) == f"tavis report: error: {os.strerror(errno.ENOSPC)} (while writing)"
    assert not (tmp_path / "results.json").exists() and _hidden(tmp_path) == []


def test_an_output_path_that_is_a_file_is_one_line(tmp_path, tmpdir_):
    a_file = tmp_path / "results"
    a_file.write_text("not a folder")
    result = _tavis([*EXPERT_EVAL, "--out", str(a_file)], tmpdir=tmpdir_)
    assert _one_line(result) == f"tavis eval: error: {a_file} is a file, not a directory"
    result = _tavis(["record", "--tasks", "conditional_pick", "--out", str(a_file / "raw")], tmpdir=tmpdir_)
    assert _one_line(result) == (f"tavis record: error: {a_file} is a file, not a directory (needed for "
                                 f"{a_file / 'raw'})")
    with pytest.raises(PathExistsError, match=f"^{a_file} is a file, not a directory$"):
        with staged_directory(a_file, overwrite=True):  # what `tavis convert --root FILE --overwrite` stages
            pass
    assert a_file.read_text() == "not a folder" and set(tmp_path.iterdir()) == {a_file, tmpdir_}


def test_a_valid_long_name_gets_its_staging_copy_and_a_name_too_long_is_one_line(tmp_path, tmpdir_):
    destination = tmp_path / ("d" * 240)
    with staged_directory(destination) as staging:
        assert len(staging.name) <= NAME_MAX_BYTES and staging.name.startswith(".ddd")
        staging.mkdir()
        (staging / "data").write_text("whole")
    with staged_directory(destination, overwrite=True) as staging:
        staging.mkdir()
    assert set(tmp_path.iterdir()) == {destination, tmpdir_} and list(destination.iterdir()) == []
    assert write_text(tmp_path / ("f" * 250), "x").read_text() == "x"
    too_long = tmp_path / ("d" * (NAME_MAX_BYTES + 1))
    result = _tavis([*EXPERT_EVAL, "--out", str(too_long)], tmpdir=tmpdir_)
    assert _one_line(result) == f"tavis eval: error: {too_long}: {os.strerror(errno.ENAMETOOLONG)}"


def test_a_killed_run_with_a_long_name_leaves_a_staging_copy_the_next_run_removes(tmp_path):
    destination = tmp_path / ("d" * 240)
    killed = subprocess.run([sys.executable, "-c", "import os, sys\n"
                             "from lerobot_tavis.staging import staged_directory\n"
                             "with staged_directory(sys.argv[1]) as staging:\n"
                             "    staging.mkdir()\n"
                             "    os.kill(os.getpid(), 9)\n", str(destination)])
    assert killed.returncode == -signal.SIGKILL and len(list(tmp_path.iterdir())) == 1
    with staged_directory(destination) as staging:
        staging.mkdir()
    assert list(tmp_path.iterdir()) == [destination]


def test_a_path_that_is_not_utf8_is_one_line_naming_the_option(tmp_path, tmpdir_):
    out = os.fsencode(tmp_path) + b"/r\xe9sultats"  # Latin-1
    result = _tavis([*EXPERT_EVAL, b"--out", out], tmpdir=tmpdir_)
    assert _one_line(result).startswith(f"tavis eval: error: --out must be UTF-8 text, got {out!r}")
    result = _tavis(["convert", out, "--repo-id", "local/x", "--root", str(tmp_path / "dataset")], tmpdir=tmpdir_)
    assert _one_line(result).startswith(f"tavis convert: error: raw_dir must be UTF-8 text, got {out!r}")
    assert list(tmp_path.iterdir()) == [tmpdir_] and list(tmpdir_.iterdir()) == []


def test_a_killed_evaluation_leaves_its_temporary_files_to_the_next_run(tmp_path, tmpdir_):
    out = tmp_path / "out"
    args = [sys.executable, "-m", "lerobot_tavis.cli", *EXPERT_EVAL, "--episodes", "4", "--chunk-episodes", "1",
            "--workers", "2", "--out", str(out)]
    process = subprocess.Popen(args, env={**os.environ, "MUJOCO_GL": "egl", "TMPDIR": str(tmpdir_)},
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 180
    while not glob.glob(f"{tmpdir_}/tavis-run-{process.pid}-*/tavis-chunk-*"):  # a worker plays a chunk
        assert process.poll() is None and time.monotonic() < deadline, "no chunk started"
        time.sleep(0.05)
    process.kill()
    process.wait()
    (left,) = tmpdir_.iterdir()  # kill -9: nothing can clean up
    assert left.name.startswith(f"tavis-run-{process.pid}-")
    assert _tavis([*EXPERT_EVAL, "--episodes", "4", "--out", str(out)], tmpdir=tmpdir_).returncode == 0
    assert list(tmpdir_.iterdir()) == []
    (cell,) = build_report(out)["cells"]
    assert cell["n"] == 4


def test_temporary_files_of_workers_and_libraries_go_with_the_run(tmp_path, tmpdir_):
    """What LeRobot leaves (a config's JSON copy) and multiprocessing's folder, in the run and its workers."""
    script = tmp_path / "leave_files.py"
    script.write_text("import multiprocessing, multiprocessing.util, tempfile\n"
                      "from lerobot_tavis.tempdir import use_private_tempdir\n"
                      "def leave():\n"
                      "    tempfile.NamedTemporaryFile('w', suffix='.json', delete=False).close()\n"
                      "    return multiprocessing.util.get_temp_dir()\n"
                      "if __name__ == '__main__':\n"
                      "    use_private_tempdir()\n"
                      "    with multiprocessing.get_context('spawn').Pool(1) as pool:\n"
                      "        print(pool.apply(leave))\n"
                      "    print(leave())\n")
    result = subprocess.run([sys.executable, str(script)], env={**os.environ, "TMPDIR": str(tmpdir_)},
                            capture_output=True, text=True, timeout=300)
    worker_dir, own_dir = result.stdout.split()
    assert all(path.startswith(f"{tmpdir_}/tavis-run-") for path in (worker_dir, own_dir)), result.stderr
    assert list(tmpdir_.iterdir()) == []


@pytest.mark.parametrize("inherited", ["default", "ignored"])
def test_a_worker_ends_on_ctrl_c_unless_its_parent_ignores_it(inherited):
    """A job a script started in the background ignores Ctrl-C, and so do its workers, instead of dying under it."""
    start = "SIG_IGN" if inherited == "ignored" else "SIG_DFL"  # what the worker found at its start, set explicitly:
    # this test's own process may have inherited SIGINT ignored
    script = (f"import signal\nsignal.signal(signal.SIGINT, signal.{start})\n"
              "from lerobot_tavis.process import leave_interrupt_to_parent\n"
              "leave_interrupt_to_parent()\nsignal.raise_signal(signal.SIGINT)\nprint('still here')\n")
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    if inherited == "ignored":
        assert (result.returncode, result.stdout) == (0, "still here\n")
    else:
        assert (result.returncode, result.stdout, result.stderr) == (128 + signal.SIGINT, "", "")


def test_ctrl_c_is_one_line_and_removes_the_staging_copy(raw_copy, tmp_path, tmpdir_):
    root = tmp_path / "dataset"
    command = [sys.executable, "-m", "lerobot_tavis.cli", "convert", str(raw_copy), "--repo-id", "local/x",
               "--root", str(root), "--image-size", "48x64", "--workers", "2"]
    # The command starts as a terminal's foreground job does, with Ctrl-C at its default, whatever this test process
    # inherited (a Python handler becomes the default across exec; an ignored signal would stay ignored).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        process = subprocess.Popen(command, env={**os.environ, "MUJOCO_GL": "egl", "TMPDIR": str(tmpdir_)},
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    finally:
        signal.signal(signal.SIGINT, previous)
    deadline = time.monotonic() + 180
    while not list(tmp_path.glob(".dataset.partial-*")):
        assert process.poll() is None and time.monotonic() < deadline, "the conversion never started staging"
        time.sleep(0.05)
    time.sleep(1.0)  # the workers replay
    os.killpg(process.pid, signal.SIGINT)  # as the terminal does: to the command and its workers
    _, stderr = process.communicate(timeout=120)
    result = subprocess.CompletedProcess(command, process.returncode, b"", stderr)
    assert _one_line(result, 128 + signal.SIGINT) == "tavis convert: interrupted"
    assert set(tmp_path.iterdir()) == {raw_copy, tmpdir_}
    assert list(tmpdir_.iterdir()) == []
