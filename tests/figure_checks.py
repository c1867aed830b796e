"""Checks on drawn figures: no two pieces of text overlap.

Measured with matplotlib's own renderer: every visible ``Text`` artist of a
figure (titles, labels, tick labels, annotations, legend entries) is drawn,
its window extent taken, and each pair tested for intersection. Empty strings
and invisible artists are skipped, and so are texts the draw leaves out: an
axis keeps tick labels for ticks outside its view limits (visible, but never
drawn), so only the texts actually drawn count. A figure made without pyplot
(``matplotlib.figure.Figure()``) gets an Agg canvas to be drawn on.
"""

import matplotlib

matplotlib.use("Agg")

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.text import Text  # noqa: E402


def _drawn_texts(fig):
    """Every ``Text`` drawn when ``fig`` is drawn, in drawing order."""
    drawn = []
    draw = Text.draw

    def recording_draw(self, renderer):
        drawn.append(self)
        return draw(self, renderer)

    Text.draw = recording_draw
    try:
        fig.canvas.draw()
    finally:
        Text.draw = draw
    return drawn


def text_boxes(fig):
    """[(text, Bbox)] of every visible, non-empty text artist drawn in ``fig`` (display units)."""
    if not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    drawn = _drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    boxes = []
    for artist in dict.fromkeys(drawn):
        if not artist.get_visible() or not artist.get_text().strip():
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
