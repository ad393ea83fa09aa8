import pytest

from lerobot_tavis.metrics.stats import wilson_interval


@pytest.mark.parametrize("successes,n,expected", [(48, 96, (40.2, 59.8)), (0, 96, (0.0, 3.8)), (96, 96, (96.2, 100.0)),
                                                  (2, 3, (20.8, 93.9))])
def test_wilson_matches_known_values(successes, n, expected):
    low, high = wilson_interval(successes, n)
    assert (round(100 * low, 1), round(100 * high, 1)) == expected


def test_wilson_edge_cases():
    assert wilson_interval(0, 0) == (0.0, 0.0)
    with pytest.raises(ValueError, match="successes must be within"):
        wilson_interval(5, 4)


def test_wilson_bounds_contain_the_rate_at_all_or_nothing():
    """Found by a protocol run whose report plot crashed: 6/6 gave an upper bound a hair below 1.0, so the error bar
    had a negative length."""
    for n in range(1, 200):
        low, high = wilson_interval(n, n)
        assert low <= 1.0 == high, n
        low, high = wilson_interval(0, n)
        assert low == 0.0 <= high, n
