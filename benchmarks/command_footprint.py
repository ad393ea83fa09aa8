"""Wall clock, CPU use and peak memory of a whole command, its worker processes included.

    python benchmarks/command_footprint.py [--out result.json] -- tavis eval --expert ... --workers 16

Samples the command's process tree (read from /proc) every `--interval` seconds and keeps the peaks of two sums:
resident memory (RSS, which counts a shared library once per process that maps it) and proportional memory (PSS,
which splits shared pages among the processes sharing them: what the tree really holds), and the largest process
count. CPU time (`cpu_s`) is the larger of two counts of the tree's user + system time: the times the operating
system adds to a parent when it waits for a child, and the sum over every process sampled in the tree of its own
time when last seen. The first alone misses processes whose parent never waits for them (a forkserver's workers,
such as a policy evaluation's env workers: this script once left them out entirely); the second misses a process's
last interval and processes that live less than one. `cores` is the number of CPUs the command may run
on (its CPU affinity, e.g. under `taskset`), `machine_busy_percent` the tree's CPU time over those cores, and
`cores_busy_percent` how busy those cores were over the run whatever ran on them (/proc/stat). Linux only.
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


def _tree(root: int) -> list[int]:
    """The process `root` and its descendants (those alive now)."""
    found, todo = [], [root]
    while todo:
        pid = todo.pop()
        found.append(pid)
        todo += _children(pid)
    return found


def _tree_memory_kib(pids: list[int]) -> tuple[int, int, int]:
    """(RSS KiB summed over `pids`, PSS KiB summed over them, how many were still alive to be read)."""
    rss_total, pss_total, count = 0, 0, 0
    for pid in pids:
        try:
            rollup = Path(f"/proc/{pid}/smaps_rollup").read_text()
        except OSError:
            continue
        fields = {line.split(":")[0]: int(line.split()[1]) for line in rollup.splitlines()[1:] if line.endswith("kB")}
        rss_total, pss_total, count = rss_total + fields["Rss"], pss_total + fields["Pss"], count + 1
    return rss_total, pss_total, count


def _own_cpu_ticks(pid: int) -> tuple[tuple[int, int], int] | None:
    """((pid, start time), the process's own user + system time) in clock ticks, None once it has gone. The start
    time tells a reused pid apart."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None
    return (pid, int(fields[19])), int(fields[11]) + int(fields[12])  # starttime; utime + stime


def _busy_and_total_ticks(cores: set[int]) -> tuple[int, int]:
    """(busy ticks, all ticks) summed over `cores` since boot, from /proc/stat (idle and iowait are not busy)."""
    busy = total = 0
    for line in Path("/proc/stat").read_text().splitlines():
        name, *values = line.split()
        if name.startswith("cpu") and name[3:].isdigit() and int(name[3:]) in cores:
            ticks = [int(v) for v in values]
            total += sum(ticks[:8])  # user nice system idle iowait irq softirq steal (guest is inside user)
            busy += sum(ticks[:8]) - ticks[3] - ticks[4]
    return busy, total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, help="also write the result as JSON here")
    parser.add_argument("--interval", type=float, default=0.5, help="memory sampling period (s)")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="the command, after --")
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give the command to measure after --")
    cores = os.sched_getaffinity(0)
    busy_before, total_before = _busy_and_total_ticks(cores)
    start = time.perf_counter()
    process = subprocess.Popen(command)
    peak_rss_kib, peak_pss_kib, peak_processes = 0, 0, 0
    last_cpu_ticks: dict[tuple[int, int], int] = {}  # (pid, start time) -> own CPU ticks when last seen
    while process.poll() is None:
        pids = _tree(process.pid)
        for sample in filter(None, map(_own_cpu_ticks, pids)):
            last_cpu_ticks[sample[0]] = sample[1]
        rss, pss, count = _tree_memory_kib(pids)
        peak_rss_kib, peak_pss_kib = max(peak_rss_kib, rss), max(peak_pss_kib, pss)
        peak_processes = max(peak_processes, count)
        time.sleep(args.interval)
    wall_s = time.perf_counter() - start
    busy_after, total_after = _busy_and_total_ticks(cores)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = max(usage.ru_utime + usage.ru_stime, sum(last_cpu_ticks.values()) / os.sysconf("SC_CLK_TCK"))
    result = {"command": " ".join(command), "returncode": process.returncode, "wall_s": round(wall_s, 1),
              "cpu_s": round(cpu_s, 1), "cpu_percent": round(100 * cpu_s / wall_s), "cores": len(cores),
              "machine_busy_percent": round(100 * cpu_s / wall_s / len(cores), 1),
              "cores_busy_percent": round(100 * (busy_after - busy_before) / max(1, total_after - total_before), 1),
              "peak_rss_gib": round(peak_rss_kib / 2**20, 2), "peak_pss_gib": round(peak_pss_kib / 2**20, 2),
              "peak_processes": peak_processes}
    print(json.dumps(result))
    if args.out:
        args.out.write_text(json.dumps(result, indent=2) + "\n")
    sys.exit(process.returncode)


if __name__ == "__main__":
    main()
