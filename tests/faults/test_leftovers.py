"""What killed runs leave behind: staging copies are removed by the next run (or at once on SIGTERM), a result
half-swapped in is restored, and `tavis report` never reads a staging copy."""

import os
import shutil
import signal
import subprocess
import sys
import time

from lerobot_tavis.cli import main
from lerobot_tavis.eval.report import build_report
from lerobot_tavis.staging import staged_directory
from tests.eval.test_report import _eval_dir


def _convert_args(raw, root) -> list[str]:
    """`tavis convert` of `raw` into `root`: one camera at 10 Hz, the least to render."""
    return ["convert", str(raw), "--repo-id", "local/x", "--root", str(root), "--image-size", "24x32",
            "--cameras", "head", "--fps", "10", "--overwrite"]


def _convert(raw, root):
    """The conversion in a process of its own, to be killed."""
    return subprocess.Popen([sys.executable, "-m", "lerobot_tavis.cli", *_convert_args(raw, root)],
                            env={**os.environ, "MUJOCO_GL": "egl"}, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)


def _partials(root):
    return sorted(root.parent.glob(f".{root.name}.partial-*"))


def _kill_once_staging(process, root, sig) -> None:
    deadline = time.monotonic() + 120
    while not _partials(root):
        assert process.poll() is None and time.monotonic() < deadline, "the conversion never started staging"
        time.sleep(0.05)
    process.send_signal(sig)
    process.wait()


def test_a_killed_conversion_leaves_a_staging_copy_that_the_next_run_removes(raw_copy, tmp_path):
    root = tmp_path / "dataset"
    _kill_once_staging(_convert(raw_copy, root), root, signal.SIGKILL)
    assert _partials(root) and not root.exists()  # kill -9 cannot clean up
    main(_convert_args(raw_copy, root))  # the next run, in this process: another process than the killed one
    assert root.is_dir() and not _partials(root)


def test_sigterm_removes_the_staging_copy_at_once(raw_copy, tmp_path):
    root = tmp_path / "dataset"
    process = _convert(raw_copy, root)
    _kill_once_staging(process, root, signal.SIGTERM)
    assert process.returncode == 128 + signal.SIGTERM
    assert not _partials(root) and not root.exists()


def test_a_result_retired_by_a_killed_swap_is_put_back(tmp_path):
    destination = tmp_path / "cell"
    dead_pid = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                              text=True).stdout.strip()
    retired = tmp_path / f".cell.old-{dead_pid}-0a1b2c3d"  # killed between its two renames
    retired.mkdir()
    (retired / "eval_info.json").write_text("{}")
    with staged_directory(destination, overwrite=True) as staging:
        assert (destination / "eval_info.json").exists() and not retired.exists()
        staging.mkdir()


def test_a_leftover_staging_copy_of_a_cell_is_not_counted(tmp_path):
    _eval_dir(tmp_path / "tavis_head__id", "id", {"conditional_pick": [True, False, True]})
    shutil.copytree(tmp_path / "tavis_head__id", tmp_path / ".tavis_head__id.partial-123-0a1b2c3d")
    (cell,) = build_report(tmp_path)["cells"]
    assert cell["n"] == 3 and cell["successes"] == 2
