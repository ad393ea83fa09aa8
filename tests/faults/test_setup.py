"""`make setup CPU=1` where PyTorch's CPU wheel index cannot be reached: one line naming the index, before anything
is installed (no .venv left behind)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make")
def test_cpu_setup_stops_in_one_line_when_the_cpu_wheel_index_is_unreachable(tmp_path):
    for name in ("Makefile", "pyproject.toml"):
        shutil.copy(REPO / name, tmp_path / name)
    unreachable = "http://127.0.0.1:9/whl/cpu"  # the discard port: nothing listens there
    result = subprocess.run(["make", "--no-print-directory", "setup", "CPU=1", f"TORCH_CPU_INDEX={unreachable}",
                             f"PYTHON={sys.executable}"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode != 0
    assert result.stdout.splitlines() == [
        f"make setup CPU=1: PyTorch's CPU wheel index {unreachable} cannot be reached from here (PyPI has no CPU-only "
        "torch for Linux): run make setup without CPU=1 (PyPI's CUDA build runs on a CPU as well)"]
    assert not (tmp_path / ".venv").exists()
