"""Figs. 7-9: no two texts overlap and none leaves the figure (measured with matplotlib's renderer).

Before the fix, the letters footnote of Figs. 7-8 ran over the rotated tick
labels, Fig. 9's over its x label, and with two participants two of Fig. 9's
point labels overlapped.
"""

import pytest

from studyapp.analysis.figures import FIGURES, render
from studyapp.analysis.rank_sum import POOLED
from studyapp.analysis.responses import check_responses
from studyapp.analysis.study import analyse
from tests.analysis.conftest import synthetic_responses
from tests.figure_checks import text_overlaps, texts_outside


def _study(participants, holm=False, task=None, seed=0):
    frame = synthetic_responses(participants=participants, trials=3, seed=seed)
    if task:
        frame = frame[frame["task"] == task]
    return analyse(check_responses(frame, "synthetic.csv"), holm=holm)


def _pooled(study):
    study.pooled_letters = True
    return study


STUDIES = {
    "paper-like, Holm": lambda: _study(9, holm=True),
    "paper-like, pooled letters": lambda: _pooled(_study(9, holm=False)),  # the most letters, longest footnote
    "two participants": lambda: _study(2),
    "rating only": lambda: _study(4, task="rating"),
}


@pytest.fixture(scope="module", params=list(STUDIES))
def study(request):
    return STUDIES[request.param]()


@pytest.mark.parametrize("name", list(FIGURES))
def test_no_text_overlaps_or_leaves_the_figure(study, name):
    figure = render(name, study)
    assert text_overlaps(figure) == []
    assert texts_outside(figure) == []


def test_box_plot_footnotes_name_the_test_behind_the_letters():
    # issue 22 item 14: within-subject letters by default; the pooled ones on request, named so
    study = _study(3)
    for name in ("fig7_adjustment", "fig8_rating"):
        footnote = render(name, study).get_supxlabel()
        assert "within subjects" in footnote and "signed-rank" in footnote and POOLED not in footnote
    study.pooled_letters = True
    for name in ("fig7_adjustment", "fig8_rating"):
        footnote = render(name, study).get_supxlabel()
        assert "Wilcoxon rank-sum" in footnote and POOLED in footnote and "(pooled, on request)" in footnote
