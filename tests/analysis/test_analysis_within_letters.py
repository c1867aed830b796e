"""Issue 22 item 14: the letters on Figs. 7-8 come from the within-subject tests, and the
participants needed are those of the test actually used (exact signed-rank, Holm over the task's pairs).

The smallest p is checked against ``scipy.stats.wilcoxon`` (exact, two-sided), not against the
code's own formula: with every difference of one sign, p = 2^(1 - n).
"""

import contextlib
import functools
import io
import itertools
import json

import numpy as np
import pytest
from scipy import stats

from studyapp.analysis.figures import render
from studyapp.stats.friedman import Friedman
from studyapp.analysis.responses import check_responses
from studyapp.stats.signed_rank import minimum_p, participants_needed
from studyapp.analysis.study import analyse
from studyapp.cli import main
from tests.analysis.conftest import SYNTHETIC_FMAX, synthetic_responses


@functools.lru_cache(maxsize=None)
def _scipy_smallest_p(n):
    """The smallest exact two-sided signed-rank p over every sign pattern of n distinct |d| (scipy)."""
    ranks = np.arange(1.0, n + 1)
    if n <= 8:
        return min(stats.wilcoxon(ranks * np.array(signs), method="exact").pvalue
                   for signs in itertools.product((1.0, -1.0), repeat=n))
    return stats.wilcoxon(ranks, method="exact").pvalue  # every sign the same: the extreme


@pytest.mark.parametrize("n", range(1, 21))
def test_the_smallest_exact_signed_rank_p_is_scipys(n):
    assert minimum_p(n) == pytest.approx(_scipy_smallest_p(n), rel=1e-12)


@pytest.mark.parametrize("pairs", [1, 3, 6, 28, 36, 45])
@pytest.mark.parametrize("alpha", [0.05, 0.01, 0.001])
def test_participants_needed_is_the_first_n_scipy_lets_through_holm(pairs, alpha):
    # Holm's first step multiplies the smallest p by the number of pairs
    n = next(n for n in range(1, 60) if pairs * _scipy_smallest_p(n) < alpha)
    assert participants_needed(alpha, pairs) == n


def test_the_issues_numbers():
    assert 36 * _scipy_smallest_p(9) == pytest.approx(0.140625)  # n = 9: 2^-8 x 36 = 0.14
    assert participants_needed(0.05, 36) == 11 and participants_needed(0.05, 28) == 11
    assert participants_needed(0.05, 1) == 6


def _study(responses, **options):
    return analyse(check_responses(responses, "synthetic"), **options)


def test_each_task_says_what_its_own_number_of_pairs_needs():
    # adjustment with 4 conditions (6 pairs: 6 x 2^(1-n) < 0.05 from n = 8), rating with 8 (28 pairs: 11)
    responses = synthetic_responses(participants=5)
    keep = ["LVT", "LEVANT", "LOWPASS", "FOAW"]
    responses = responses[(responses["task"] == "rating") | responses["condition"].isin(keep)]
    lines = _study(responses).sample_size_warnings()
    adjustment = next(line for line in lines if line.startswith("adjustment: no pair"))
    rating = next(line for line in lines if line.startswith("rating: no pair"))
    assert "over the 6 pairs" in adjustment and adjustment.endswith("8 participants are needed")
    assert "over the 28 pairs" in rating and rating.endswith("11 participants are needed")
    assert "6 participants are needed" not in " ".join(lines)  # the uncorrected count the report gave


def _figure_letters(study, name="fig7_adjustment"):
    figure = render(name, study)
    ax = figure.axes[0]
    names = [label.get_text() for label in ax.get_xticklabels()]
    letters = [text.get_text() for text in ax.texts]
    return dict(zip(names, letters)), figure.get_supxlabel()


def test_nine_participants_figure_letters_are_the_within_subject_ones():
    # The issue: Figs. 7-8 showed the pooled rank-sum letters (several groups) while the valid
    # within-subject tests, Holm over 36 pairs with 9 participants, cannot find any difference.
    study = _study(synthetic_responses(participants=9))
    assert len(set("".join(study.adjustment.pooled_letters.values()))) > 2  # pooled: several groups
    assert not study.adjustment.within.signed_rank["significant"].any()
    drawn, footnote = _figure_letters(study)
    assert drawn == study.adjustment.letters and set(drawn.values()) == {"a"}
    assert "within subjects (9 participants: Friedman" in footnote and "Holm-corrected" in footnote
    assert "pooled" not in footnote
    drawn, footnote = _figure_letters(study, "fig8_rating")
    assert drawn == study.rating.letters


def test_pooled_letters_only_on_request_and_labelled():
    study = _study(synthetic_responses(participants=9), pooled_letters=True)
    drawn, footnote = _figure_letters(study)
    assert drawn == study.adjustment.pooled_letters and len(set("".join(drawn.values()))) > 2
    assert footnote.startswith("letters (pooled, on request)") and "rank-sum" in footnote


def test_within_subject_letters_follow_the_holm_tests_when_there_are_enough_participants():
    study = _study(synthetic_responses(participants=14, seed=3))
    within = study.adjustment.within
    assert within.friedman.p_value < 0.05
    different = set(within.different_pairs(0.05))
    assert different  # LVT (20 N) against FOAW (5 N) in every participant: 14 of one sign
    assert ("LVT", "FOAW") in different
    letters = study.adjustment.letters
    for a, b in itertools.combinations(SYNTHETIC_FMAX, 2):
        share = bool(set(letters[a]) & set(letters[b]))
        assert share == ((a, b) not in different and (b, a) not in different), (a, b)


def test_friedman_must_reject_before_a_pair_counts():
    within = _study(synthetic_responses(participants=14, seed=3)).adjustment.within
    assert within.different_pairs(0.05)
    within.friedman = Friedman(statistic=3.0, p_value=0.2, n_participants=14, n_conditions=9)
    assert within.different_pairs(0.05) == []


def test_analyse_pooled_letters_option(tmp_path):
    synthetic_responses(participants=9).to_csv(tmp_path / "r.csv", index=False)
    for options, pooled in (([], False), (["--pooled-letters"], True)):
        out = tmp_path / f"out{int(pooled)}"
        with contextlib.redirect_stderr(io.StringIO()):
            assert main(["analyse", str(tmp_path / "r.csv"), "-o", str(out), *options]) == 0
        assert json.loads((out / "analysis_settings.json").read_text())["pooled_letters"] is pooled
        html = (out / "report.html").read_text()
        assert "letters (within-subject)" in html
        assert ("letters (pooled rank-sum)" in html) is pooled
