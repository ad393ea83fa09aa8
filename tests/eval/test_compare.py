"""`tavis compare`: two evaluations paired by (task, split, seed) and the exact McNemar test."""

import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.eval.compare import compare_evaluations
from lerobot_tavis.metrics.stats import mcnemar_exact_p

from .test_report import _eval_dir


def test_pairs_the_scored_episodes_by_seed(tmp_path, capsys):
    _eval_dir(tmp_path / "a" / "tavis_head__id", "id", {"conditional_pick": [True, True, True, False, False]})
    _eval_dir(tmp_path / "b" / "tavis_head__id", "id", {"conditional_pick": [True, False, False, True, False, True]})
    outcomes = compare_evaluations(tmp_path / "a", tmp_path / "b")  # b's sixth seed has no partner in a
    assert (outcomes.paired, outcomes.both, outcomes.only_a, outcomes.only_b) == (5, 1, 2, 1)
    main(["compare", str(tmp_path / "a"), str(tmp_path / "b")])
    assert capsys.readouterr().out.startswith("5 paired episodes: A 3 successes, B 2; both 1, only A 2, only B 1;")


def test_evaluations_of_other_episodes_are_refused_in_one_line(tmp_path, capsys):
    _eval_dir(tmp_path / "a" / "tavis_head__id", "id", {"conditional_pick": [True]})
    _eval_dir(tmp_path / "b" / "tavis_head__ood", "ood_spatial", {"conditional_pick": [True]})
    with pytest.raises(SystemExit, match="share no episode"):
        main(["compare", str(tmp_path / "a"), str(tmp_path / "b")])


def test_exact_mcnemar_p_values():
    assert mcnemar_exact_p(0, 0) == 1.0
    assert mcnemar_exact_p(11, 17) == pytest.approx(0.345, abs=1e-3)  # 2 * P(X <= 11), X ~ B(28, 1/2)
    assert mcnemar_exact_p(0, 6) == pytest.approx(2 / 64)
    assert mcnemar_exact_p(5, 5) == 1.0
