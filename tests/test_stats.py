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
