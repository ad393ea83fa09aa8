"""benchmarks/command_footprint.py: CPU time of a command's whole process tree, workers nobody waits for included."""

import json
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "command_footprint.py"

# Two forkserver workers each burn 1.5 s of CPU. Their parent, the forkserver, is never waited for by the command,
# so the operating system's children times of the command leave them out.
BURN = """
import multiprocessing, time

def burn(_):
    start = time.process_time()
    while time.process_time() - start < 1.5:
        pass

if __name__ == "__main__":
    with multiprocessing.get_context("forkserver").Pool(2) as pool:
        pool.map(burn, range(2))
"""


def test_counts_the_cpu_time_of_forkserver_workers(tmp_path):
    script = tmp_path / "burn.py"
    script.write_text(BURN)
    out = tmp_path / "footprint.json"
    subprocess.run([sys.executable, str(SCRIPT), "--interval", "0.1", "--out", str(out), "--", sys.executable,
                    str(script)], check=True, capture_output=True)
    result = json.loads(out.read_text())
    assert result["returncode"] == 0
    assert result["cpu_s"] >= 2.4  # 3 s burnt; at most the last 0.1 s of each process goes unseen
    assert 0 <= result["cores_busy_percent"] <= 100
    assert result["peak_processes"] >= 3  # the command, its forkserver and a worker at least
