"""Point labels that never overlap: a simple, deterministic placement.

``place_labels(ax, xy, texts)`` annotates each data point with its text. It
works in display pixels with matplotlib's renderer, once the figure's layout
is final (call it after ``tight_layout`` and colour bars, and do not lay the
figure out again). Labels are placed one at a time, in a fixed order (left to
right, then bottom to top, then by text), so the same data always gives the
same figure. For each label, candidate boxes are tried on rings around its
point: the eight compass positions next to the marker first, then positions
at growing distances in sixteen directions. A candidate is taken when its box

1. lies inside the axes (so it cannot touch tick labels, axis labels or
   titles, which are outside),
2. intersects no label already placed and no box in ``avoid`` (a legend), and
3. covers no marker, in the first pass; a second pass drops this wish.

A label moved off its ring-1 position gets a thin leader line to its point.
If no candidate fits at all, the labels are laid out again one point smaller
(down to ``MIN_FONTSIZE``); at the last size a label that still does not fit
goes to the free cell of a grid over the axes nearest its point, or, with no
free cell left, is not drawn (never drawn over another text).
"""

import math

MIN_FONTSIZE = 4.0
GAP_PX = 2.0  # clear space between a box and its neighbours
RINGS = 12


def _directions(n):
    return [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]


COMPASS = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)]


class _Box:
    __slots__ = ("x0", "y0", "x1", "y1")

    def __init__(self, x0, y0, x1, y1):
        self.x0, self.y0, self.x1, self.y1 = x0, y0, x1, y1

    @classmethod
    def around(cls, cx, cy, w, h):
        return cls(cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)

    def hits(self, other, gap=GAP_PX):
        return (min(self.x1, other.x1) - max(self.x0, other.x0) > -gap
                and min(self.y1, other.y1) - max(self.y0, other.y0) > -gap)

    def inside(self, outer, gap=GAP_PX):
        return (self.x0 >= outer.x0 + gap and self.y0 >= outer.y0 + gap
                and self.x1 <= outer.x1 - gap and self.y1 <= outer.y1 - gap)


def _candidates(px, py, w, h, radius):
    """Centres of candidate boxes around a point, nearest first, with their ring number."""
    for dx, dy in COMPASS:
        yield 1, (px + dx * (radius + w / 2), py + dy * (radius + h / 2))
    step = h + GAP_PX
    for ring in range(2, RINGS + 1):
        reach = radius + (ring - 1) * step
        for dx, dy in _directions(16):
            yield ring, (px + dx * (reach + w / 2), py + dy * (reach + h / 2))


def _grid(frame, w, h):
    """Centres of a grid of boxes of size w x h covering ``frame``."""
    nx = max(1, int((frame.x1 - frame.x0) // (w + GAP_PX)))
    ny = max(1, int((frame.y1 - frame.y0) // (h + GAP_PX)))
    for i in range(nx):
        for j in range(ny):
            yield (frame.x0 + (i + 0.5) * (frame.x1 - frame.x0) / nx,
                   frame.y0 + (j + 0.5) * (frame.y1 - frame.y0) / ny)


def _layout(points, sizes, frame, avoid, radius, last):
    """Box centres (pixels) and ring numbers for every label, or None if one does not fit.

    On the ``last`` try a label that fits nowhere, not even on the grid, is
    left out (its entry is None) rather than drawn over another.
    """
    markers = [_Box.around(px, py, 2 * radius, 2 * radius) for px, py in points]
    placed = list(avoid)
    out = []
    for i, ((px, py), (w, h)) in enumerate(zip(points, sizes)):
        chosen = None
        for clear_of_markers in (True, False):
            for ring, (cx, cy) in _candidates(px, py, w, h, radius):
                box = _Box.around(cx, cy, w, h)
                if not box.inside(frame) or any(box.hits(b) for b in placed):
                    continue
                if clear_of_markers and any(box.hits(m, 0.0) for j, m in enumerate(markers) if j != i):
                    continue
                chosen = (ring, cx, cy, box)
                break
            if chosen:
                break
        if chosen is None and last:
            free = [(cx, cy) for cx, cy in _grid(frame, w, h)
                    if not any(_Box.around(cx, cy, w, h).hits(b) for b in placed)]
            if free:
                cx, cy = min(free, key=lambda c: ((c[0] - px) ** 2 + (c[1] - py) ** 2, c))
                chosen = (RINGS + 1, cx, cy, _Box.around(cx, cy, w, h))
        if chosen is None:
            if not last:
                return None
            out.append(None)
            continue
        placed.append(chosen[3])
        out.append(chosen)
    return out


def _edge(px, py, box):
    """Where the segment from the point to the box's centre enters the box."""
    cx, cy = (box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2
    ux, uy = px - cx, py - cy
    s = min((box.x1 - box.x0) / 2 / abs(ux) if ux else math.inf, (box.y1 - box.y0) / 2 / abs(uy) if uy else math.inf)
    return cx + ux * s, cy + uy * s


def place_labels(ax, xy, texts, fontsize=7.0, avoid=(), marker_px=4.0, color="0.15"):
    """Annotate point ``xy[i]`` (data coordinates) with ``texts[i]``; return the annotations (None if left out).

    ``avoid``: artists (e.g. a legend) whose boxes the labels must keep clear
    of; ``marker_px``: the markers' radius in pixels. Leader lines are plain
    lines (not annotation arrows), so a label's box is its text's alone.
    """
    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax.set_xlim(ax.get_xlim())  # labels are placed for these limits: keep them
    ax.set_ylim(ax.get_ylim())
    e = ax.get_window_extent(renderer)
    frame = _Box(e.x0, e.y0, e.x1, e.y1)
    blocked = [_Box(b.x0, b.y0, b.x1, b.y1) for b in (a.get_window_extent(renderer) for a in avoid)]
    pixels = [tuple(ax.transData.transform(p)) for p in xy]
    order = sorted(range(len(texts)), key=lambda i: (round(pixels[i][0], 3), round(pixels[i][1], 3), texts[i]))
    size = float(fontsize)
    while True:
        last = size - 1.0 < MIN_FONTSIZE
        sizes = []
        for i in order:
            probe = ax.text(0, 0, texts[i], fontsize=size)
            b = probe.get_window_extent(renderer)
            sizes.append((b.width, b.height))
            probe.remove()
        layout = _layout([pixels[i] for i in order], sizes, frame, blocked, marker_px + GAP_PX, last)
        if layout is not None:
            break
        size -= 1.0
    to_points = 72.0 / fig.dpi
    to_data = ax.transData.inverted()
    labels = [None] * len(texts)
    for i, placed in zip(order, layout):
        if placed is None:
            continue
        ring, cx, cy, box = placed
        px, py = pixels[i]
        if ring > 1:
            end = to_data.transform([(px, py), _edge(px, py, box)])
            ax.plot(end[:, 0], end[:, 1], color="0.6", lw=0.5, zorder=1)
        labels[i] = ax.annotate(
            texts[i], xy[i], xytext=((cx - px) * to_points, (cy - py) * to_points), textcoords="offset points",
            ha="center", va="center", fontsize=size, color=color, annotation_clip=False,
        )
    return labels
