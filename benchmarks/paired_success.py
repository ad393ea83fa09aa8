"""Two evaluations of the same seeds compared episode by episode: how many seeds succeed in both, only in A, only
in B, and the exact McNemar test on the discordant ones (two-sided binomial test of "only A" against "only B").

    python benchmarks/paired_success.py EVAL_A EVAL_B

EVAL_A and EVAL_B are `tavis eval` output folders (or any folders holding `episodes.jsonl` files below them); episodes
are paired by (task, split, seed), and only pairs present in both count.
"""

from __future__ import annotations

import argparse
import json
from math import comb
from pathlib import Path


def outcomes(folder: Path) -> dict[tuple[str, str, int], bool]:
    """(task, split, seed) -> success of every episode logged under `folder`."""
    logs = sorted(folder.rglob("episodes.jsonl"))
    if not logs:
        raise SystemExit(f"{folder}: no episodes.jsonl below it")
    records = (json.loads(line) for log in logs for line in log.read_text().splitlines() if line.strip())
    return {(r["task"], r["split"], r["seed"]): bool(r["success"]) for r in records}


def mcnemar_exact_p(only_a: int, only_b: int) -> float:
    """Two-sided exact McNemar p-value: the discordant pairs as a binomial(only_a + only_b, 1/2) draw."""
    n = only_a + only_b
    if n == 0:
        return 1.0
    tail = sum(comb(n, k) for k in range(min(only_a, only_b) + 1)) / 2 ** n
    return min(1.0, 2 * tail)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("eval_a", type=Path)
    parser.add_argument("eval_b", type=Path)
    args = parser.parse_args()
    a, b = outcomes(args.eval_a), outcomes(args.eval_b)
    shared = sorted(a.keys() & b.keys())
    if not shared:
        raise SystemExit("the two evaluations share no (task, split, seed)")
    both = sum(a[k] and b[k] for k in shared)
    only_a = sum(a[k] and not b[k] for k in shared)
    only_b = sum(b[k] and not a[k] for k in shared)
    print(f"{len(shared)} paired episodes: A {both + only_a} successes, B {both + only_b}; both {both}, only A "
          f"{only_a}, only B {only_b}; exact McNemar p = {mcnemar_exact_p(only_a, only_b):.3f}")


if __name__ == "__main__":
    main()
