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


def _scatter_study(points):
    """A stand-in StudyAnalysis for Fig. 9: condition -> (median noisiness, median max F_max)."""
    from types import SimpleNamespace

    import pandas as pd

    def summary(column):
        rows = [(c, v[column], v[column] * 0.95, v[column] * 1.05) for c, v in points.items()]
        return pd.DataFrame(rows, columns=["condition", "median", "q1", "q3"])

    return SimpleNamespace(rating=SimpleNamespace(summary=summary(0)), adjustment=SimpleNamespace(summary=summary(1)))


# The case: KALLEV at (0.724, 5.36 N) and LEASTSQ at (0.748, 5.17 N), their labels by each other's markers.
CLOSE_POINTS = {
    "LVT": (0.05, 9.8), "LEVANT": (0.95, 6.1), "KALPOS": (0.62, 5.9), "LOWPASS": (0.55, 5.6),
    "KALLEV": (0.724, 5.36), "LEASTSQ": (0.748, 5.17), "LEVANTLP": (0.70, 5.0), "FOAW": (0.85, 4.2),
}


@pytest.mark.parametrize("points", [CLOSE_POINTS, {n: (x, y * 0.2 + 4.0) for n, (x, y) in CLOSE_POINTS.items()}])
def test_fig9_labels_sit_by_their_own_markers(points):
    """Every label's anchor, and the middle of its text, is nearer its own point than any other point.

    The anchor is where the annotation is attached: its point plus its offset (in points).
    """
    figure = render("fig9_scatter", _scatter_study(points))
    figure.draw_without_rendering()
    ax = figure.axes[0]
    labels = [t for t in ax.texts if t.get_text() in points]
    assert len(labels) == len(points)
    pixels = {t.get_text(): ax.transData.transform(t.xy) for t in labels}
    for label in labels:
        box = label.get_window_extent()
        x, y = pixels[label.get_text()]
        dx, dy = label.get_position()
        anchor = (x + dx * figure.dpi / 72, y + dy * figure.dpi / 72)
        for spot in (anchor, ((box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2)):
            nearest = min(pixels, key=lambda n: (spot[0] - pixels[n][0]) ** 2 + (spot[1] - pixels[n][1]) ** 2)
            assert nearest == label.get_text(), f"{label.get_text()}'s label is nearest {nearest}'s marker"
    assert not text_overlaps(figure)
