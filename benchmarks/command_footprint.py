"""Wall clock, CPU use and peak memory of a whole command, its worker processes included.

    python benchmarks/command_footprint.py [--out result.json] -- tavis eval --expert ... --workers 16

Samples the memory of the command's process tree (read from /proc) every `--interval` seconds and keeps the peaks
of two sums: resident memory (RSS, which counts a shared library once per process that maps it) and proportional
memory (PSS, which splits shared pages among the processes sharing them: what the tree really holds), and the
largest process count; CPU time is the tree's user + system time (every descendant
that was waited for is counted by the operating system in its parent's children times). `cores` is the number of
CPUs the command may run on (its CPU affinity, e.g. under `taskset`), and `machine_busy_percent` its CPU use over
those. Linux only.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path


def _children(pid: int) -> list[int]:
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            continue
    return found


def _tree_memory_kib(root: int) -> tuple[int, int, int]:
    """(RSS KiB summed over the tree, PSS KiB summed over the tree, processes in the tree)."""
    rss_total, pss_total, count, todo = 0, 0, 0, [root]
    while todo:
        pid = todo.pop()
        try:
            rollup = Path(f"/proc/{pid}/smaps_rollup").read_text()
        except OSError:
            continue
        fields = {line.split(":")[0]: int(line.split()[1]) for line in rollup.splitlines()[1:] if line.endswith("kB")}
        rss_total, pss_total, count = rss_total + fields["Rss"], pss_total + fields["Pss"], count + 1
        todo += _children(pid)
    return rss_total, pss_total, count


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, help="also write the result as JSON here")
    parser.add_argument("--interval", type=float, default=0.5, help="memory sampling period (s)")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="the command, after --")
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give the command to measure after --")
    start = time.perf_counter()
    process = subprocess.Popen(command)
    peak_rss_kib, peak_pss_kib, peak_processes = 0, 0, 0
    while process.poll() is None:
        rss, pss, count = _tree_memory_kib(process.pid)
        peak_rss_kib, peak_pss_kib = max(peak_rss_kib, rss), max(peak_pss_kib, pss)
        peak_processes = max(peak_processes, count)
        time.sleep(args.interval)
    wall_s = time.perf_counter() - start
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = usage.ru_utime + usage.ru_stime
    cores = len(os.sched_getaffinity(0))
    result = {"command": " ".join(command), "returncode": process.returncode, "wall_s": round(wall_s, 1),
              "cpu_s": round(cpu_s, 1), "cpu_percent": round(100 * cpu_s / wall_s), "cores": cores,
              "machine_busy_percent": round(100 * cpu_s / wall_s / cores, 1),
              "peak_rss_gib": round(peak_rss_kib / 2**20, 2), "peak_pss_gib": round(peak_pss_kib / 2**20, 2),
              "peak_processes": peak_processes}
    print(json.dumps(result))
    if args.out:
        args.out.write_text(json.dumps(result, indent=2) + "\n")
    sys.exit(process.returncode)


if __name__ == "__main__":
    main()
