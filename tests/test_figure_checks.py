"""The figure checks themselves: overlaps and texts outside found, tick labels that are never drawn ignored."""

from matplotlib.figure import Figure

from tests.figure_checks import text_overlaps, texts_outside


def _figure():
    figure = Figure(figsize=(4, 3))  # no pyplot: the checks give it a canvas
    ax = figure.add_subplot(1, 1, 1)
    ax.plot([0, 1], [0, 1])
    ax.set_ylim(-0.05, 1.05)  # the locator also makes ticks -0.2 and 1.2, outside the view: never drawn
    return figure, ax


def test_a_clean_figure_passes_despite_ticks_outside_the_view():
    figure, ax = _figure()
    assert texts_outside(figure) == [] and text_overlaps(figure) == []
    # The undrawn labels exist, visible, beyond the axes: what the checks must leave out.
    undrawn = [t for t in ax.get_yticklabels() if t.get_text() in ("\u22120.2", "1.2")]
    assert len(undrawn) == 2 and all(t.get_visible() for t in undrawn)


def test_overlapping_and_outside_texts_are_found():
    figure, ax = _figure()
    ax.text(0.5, 0.5, "first label")
    ax.text(0.5, 0.5, "second label")
    figure.text(0.95, 0.5, "cut off at the right edge")
    assert ("first label", "second label") in text_overlaps(figure)
    assert texts_outside(figure) == ["cut off at the right edge"]
