"""Two evaluations of the same episodes compared seed by seed (`tavis compare`): how many succeed in both, only in
the first, only in the second, and the exact McNemar test on the discordant ones."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lerobot_tavis.errors import InputError
from lerobot_tavis.eval.outputs import eval_dirs, join
from lerobot_tavis.metrics.stats import mcnemar_exact_p


@dataclass(frozen=True)
class PairedOutcomes:
    """Success counts over the episodes two evaluations share, paired by (task, split, seed)."""

    paired: int
    both: int
    only_a: int
    only_b: int

    @property
    def p_value(self) -> float:
        return mcnemar_exact_p(self.only_a, self.only_b)

    def summary(self) -> str:
        p = f"p = {self.p_value:.3f}" if self.p_value >= 0.001 else "p < 0.001"
        return (f"{self.paired} paired episodes: A {self.both + self.only_a} successes, B {self.both + self.only_b}; "
                f"both {self.both}, only A {self.only_a}, only B {self.only_b}; exact McNemar {p}")


def episode_outcomes(root: Path) -> dict[tuple[str, str, int], bool]:
    """(task, split, seed) -> success of every scored episode of the evaluations under `root`."""
    return {(record["task"], record["split"], record["seed"]): bool(record["success"])
            for eval_dir in eval_dirs(root) for record in join(eval_dir)[0]}


def compare_evaluations(root_a: str | Path, root_b: str | Path) -> PairedOutcomes:
    a, b = episode_outcomes(Path(root_a)), episode_outcomes(Path(root_b))
    shared = a.keys() & b.keys()
    if not shared:
        raise InputError(f"{root_a} and {root_b} share no episode (task, split and seed)")
    return PairedOutcomes(paired=len(shared), both=sum(a[k] and b[k] for k in shared),
                          only_a=sum(a[k] and not b[k] for k in shared), only_b=sum(b[k] and not a[k] for k in shared))


def run_compare(options) -> list[str]:
    return [compare_evaluations(options.eval_a, options.eval_b).summary()]
