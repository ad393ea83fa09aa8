"""Success statistics."""

from __future__ import annotations

import math

Z_95 = 1.96


def wilson_interval(successes: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval of a success rate (docs/reference.md §8), clipped to [0, 1]; (0, 0) when n = 0. The bounds
    always contain the rate: at 0 or n successes the formula's bound equals it exactly, and rounding may otherwise
    put it a hair on the wrong side (6/6 gave an upper bound of 0.9999999999999999)."""
    if not 0 <= successes <= n:
        raise ValueError(f"successes must be within 0..n={n}, got {successes}")
    if n == 0:
        return 0.0, 0.0
    p = successes / n
    denominator = 1 + z**2 / n
    centre = (p + z**2 / (2 * n)) / denominator
    half_width = z / denominator * math.sqrt(p * (1 - p) / n + z**2 / (4 * n**2))
    return max(0.0, min(p, centre - half_width)), min(1.0, max(p, centre + half_width))


def mcnemar_exact_p(only_a: int, only_b: int) -> float:
    """Two-sided exact McNemar p-value of paired successes: the discordant pairs (successes of one side only) as a
    binomial(only_a + only_b, 1/2) draw; 1.0 when there are none."""
    n = only_a + only_b
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, k) for k in range(min(only_a, only_b) + 1)) / 2**n
    return min(1.0, 2 * tail)
