"""Checks on drawn figures: no two pieces of text overlap.

Measured with matplotlib's own renderer: every visible ``Text`` artist of a
figure (titles, labels, tick labels, annotations, legend entries) is drawn,
its window extent taken, and each pair tested for intersection. Empty strings
and invisible artists are skipped, and so are the labels of ticks that lie
outside their axis's view: matplotlib keeps those artists (at positions past
the axes) but does not draw them.
"""

import matplotlib

matplotlib.use("Agg")

from matplotlib.axis import Axis  # noqa: E402
from matplotlib.text import Text  # noqa: E402


def _undrawn_tick_labels(fig):
    """Tick labels that the last draw left out (their tick is outside the view)."""
    undrawn = set()
    for axis in fig.findobj(Axis):
        drawn = {id(t) for t in axis._update_ticks()}  # the ticks Axis.draw draws
        for tick in axis.get_major_ticks() + axis.get_minor_ticks():
            if id(tick) not in drawn:
                undrawn.update((id(tick.label1), id(tick.label2)))
    return undrawn


def text_boxes(fig):
    """[(text, Bbox)] of every visible, non-empty text artist in ``fig`` (display units)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    undrawn = _undrawn_tick_labels(fig)
    boxes = []
    for artist in fig.findobj(Text):
        if not artist.get_visible() or not artist.get_text().strip() or id(artist) in undrawn:
            continue
        box = artist.get_window_extent(renderer)
        if box.width <= 0 or box.height <= 0:
            continue
        boxes.append((artist.get_text(), box))
    return boxes


def text_overlaps(fig, pad=0.0):
    """Pairs ``(text_a, text_b)`` whose boxes intersect (by more than ``pad`` pixels)."""
    boxes = text_boxes(fig)
    pairs = []
    for i, (ta, a) in enumerate(boxes):
        for tb, b in boxes[i + 1:]:
            width = min(a.x1, b.x1) - max(a.x0, b.x0)
            height = min(a.y1, b.y1) - max(a.y0, b.y0)
            if width > pad and height > pad:
                pairs.append((ta, tb))
    return pairs


def texts_outside(fig):
    """Texts whose box extends past the figure's edges (clipped when saved)."""
    bounds = fig.bbox
    return [t for t, b in text_boxes(fig)
            if b.x0 < bounds.x0 - 1 or b.y0 < bounds.y0 - 1 or b.x1 > bounds.x1 + 1 or b.y1 > bounds.y1 + 1]
