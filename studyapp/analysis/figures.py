"""The paper's figures from a ``StudyAnalysis``: Fig. 7 and 8 box plots, Fig. 9 scatter.

Figures are ``matplotlib.figure.Figure`` objects built without pyplot, so the
same drawing code renders to files (Agg, PNG and SVG) and into the GUI's Qt
canvas. Boxes follow matplotlib's defaults (median line, quartile box,
whiskers to the furthest sample within 1.5 IQR of the box); every sample is
drawn over its box, outliers included, so no separate outlier marks. Conditions run best first, left to right, as in
the paper. The letters above the boxes are a compact letter display
(compact_letters.py): two conditions sharing a letter are not significantly
different. By default they come from the within-subject tests, participants
as the units (Friedman's test, then Holm-corrected pairwise signed-rank
tests: study.py); with ``pooled_letters`` (``analyse --pooled-letters``) from
the paper's pairwise rank-sum tests on trials pooled across participants,
and the footnote then says they are pooled. The footnote is the figure's
``supxlabel``, so the constrained layout keeps room for it below the tick
labels and the x label instead of drawing it over them.
"""

import numpy as np
from matplotlib.figure import Figure
from matplotlib.transforms import blended_transform_factory

from studyapp.analysis.counted import counted
from studyapp.analysis.rank_sum import POOLED
from studyapp.io.atomic import atomic_path

FORMATS = ("png", "svg")
_SIZE = (7.5, 4.8)


def draw_adjustment(figure, study):
    """Fig. 7: maximum friction force F_max per condition (adjustment task)."""
    _draw_box_plot(
        figure,
        study.adjustment,
        study,
        ylabel="max $F_{max}$ (N)",
        title="Fig. 7: maximum friction force $F_{max}$ (adjustment task)",
    )


def draw_rating(figure, study):
    """Fig. 8: normalised noisiness rating per condition (rating task)."""
    _draw_box_plot(
        figure,
        study.rating,
        study,
        ylabel="noisiness (0 = least, 1 = most noisy)",
        title="Fig. 8: subjective noisiness (rating task)",
    )
    if study.rating.groups:
        figure.axes[0].set_ylim(-0.05, 1.05)


def draw_scatter(figure, study):
    """Fig. 9: median noisiness against median max F_max per condition; top left is better."""
    ax = figure.add_subplot(1, 1, 1)
    rating = study.rating.summary.set_index("condition")
    adjustment = study.adjustment.summary.set_index("condition")
    common = [c for c in adjustment.index if c in rating.index]
    ax.set_title("Fig. 9: median noisiness against median max $F_{max}$")
    ax.set_xlabel("median noisiness (normalised)")
    ax.set_ylabel("median max $F_{max}$ (N)")
    if not common:
        _say(ax, "no condition appears in both tasks")
        return
    x = rating.loc[common, "median"].to_numpy()
    y = adjustment.loc[common, "median"].to_numpy()
    xerr = np.vstack([x - rating.loc[common, "q1"].to_numpy(), rating.loc[common, "q3"].to_numpy() - x])
    yerr = np.vstack([y - adjustment.loc[common, "q1"].to_numpy(), adjustment.loc[common, "q3"].to_numpy() - y])
    ax.errorbar(x, y, xerr=xerr, yerr=yerr, fmt="none", ecolor="0.75", elinewidth=1, zorder=1)
    ax.scatter(x, y, s=36, color="C0", zorder=2)
    ax.grid(True, alpha=0.3)
    _footnote(figure, "points: medians; bars: quartiles; top left is better")
    labels = [
        ax.annotate(plain(name), (xi, yi), xytext=(5, 4), textcoords="offset points", fontsize=9, va="bottom")
        for name, xi, yi in zip(common, x, y)
    ]
    _place_labels(figure, ax, labels)


FIGURES = {
    "fig7_adjustment": draw_adjustment,
    "fig8_rating": draw_rating,
    "fig9_scatter": draw_scatter,
}


def render(name, study):
    """A new ``Figure`` holding figure ``name`` (a key of ``FIGURES``) of ``study``."""
    figure = Figure(figsize=_SIZE, layout="constrained")
    FIGURES[name](figure, study)
    return figure


def save_figure(figure, directory, stem):
    """Write ``figure`` as ``directory/stem.png`` and ``.svg`` (atomically); the paths written."""
    paths = []
    for fmt in FORMATS:
        target = directory / f"{stem}.{fmt}"
        with atomic_path(target) as tmp:
            figure.savefig(tmp, format=fmt, dpi=120)
        paths.append(target)
    return paths


def _draw_box_plot(figure, task, study, ylabel, title):
    ax = figure.add_subplot(1, 1, 1)
    # Room between the axes and the title for the letters.
    ax.set_title(title, pad=16)
    ax.set_ylabel(ylabel)
    if not task.groups:
        _say(ax, f"no {task.task} responses")
        return
    names = task.conditions
    data = [task.groups[c] for c in names]
    positions = np.arange(1, len(names) + 1)
    ax.boxplot(data, positions=positions, widths=0.55, tick_labels=[plain(n) for n in names], showfliers=False,
               medianprops={"color": "C3", "linewidth": 1.8})
    jitter = np.random.default_rng(0)
    for x, values in zip(positions, data):
        ax.scatter(x + jitter.uniform(-0.18, 0.18, values.size), values, s=9, color="C0", alpha=0.45,
                   linewidths=0, zorder=3)
    above = blended_transform_factory(ax.transData, ax.transAxes)
    letters, source = study.figure_letters(task)
    for x, name in zip(positions, names):
        ax.text(x, 1.01, letters[name], transform=above, ha="center", va="bottom", fontsize=9)
    ax.tick_params(axis="x", labelrotation=30)
    ax.grid(True, axis="y", alpha=0.3)
    _footnote(figure, letters_footnote(study, task, source) + simulated_footnote(study, task))


def simulated_footnote(study, task):
    """With simulated participants analysed (--include-simulated): how many of the task's participants they are."""
    if not study.include_simulated:
        return ""
    responses = study.responses
    rows = responses[responses["task"] == task.task]
    everyone = rows["participant"].astype(str).unique()
    simulated = rows.loc[rows["simulated"].astype(bool), "participant"].astype(str).unique() \
        if "simulated" in rows else []
    return f"\n{len(simulated)} of {counted(len(everyone), 'participant')} simulated (--include-simulated)"


def letters_footnote(study, task, source):
    """What the letters over a box plot come from, in the figure's words."""
    if source == "pooled":
        correction = ", Holm-corrected" if study.holm else ", uncorrected"
        return (f"letters (pooled, on request): conditions sharing a letter do not differ (Wilcoxon rank-sum, "
                f"p < {study.alpha:g}{correction}),\n{POOLED}")
    n = task.within.n_participants
    return (f"letters: conditions sharing a letter do not differ within subjects ({counted(n, 'participant')}: "
            "Friedman, "
            f"then Wilcoxon signed-rank,\nHolm-corrected, p < {study.alpha:g})")


def plain(text):
    """``text`` shown as written: a condition named ``$\\frac$`` is not matplotlib's maths (it crashed the
    report: issue 33, item 6), so every ``$`` is escaped."""
    return str(text).replace("$", r"\$")


def _footnote(figure, text):
    figure.supxlabel(plain(text), x=0.01, ha="left", fontsize=8, color="0.35")


# Label positions tried around a point, nearest first: (dx, dy) in points from the point to the
# label's anchor (the corner or edge given by the alignment), and that alignment.
_LABEL_SPOTS = [
    (dx * sx, dy * sy, "left" if sx > 0 else "right", "bottom" if sy > 0 else "top")
    for dx, dy in ((5, 4), (5, 14), (12, 24))
    for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1))
] + [(7, 0, "left", "center"), (-7, 0, "right", "center"), (0, 7, "center", "bottom"), (0, -7, "center", "top")]


def _place_labels(figure, ax, labels):
    """Move each point label to the first spot that is its point's alone, clear of earlier labels, in the axes.

    A spot is its point's alone when the label's anchor and the middle of its
    box are both nearer its own point than any other point, and the box
    covers no other point: a reader then pairs every label with its marker
    (two close points each get the side away from the other). Measured with
    the renderer after the layout is done (labels are kept out of the layout,
    so moving them cannot move the axes). When no spot is free, the one with
    the least overlap and ambiguity is kept.
    """
    for label in labels:
        label.set_in_layout(False)
    figure.draw_without_rendering()
    frame = ax.get_window_extent()
    points = [ax.transData.transform(label.xy) for label in labels]
    placed = []
    for i, label in enumerate(labels):
        best = None
        for dx, dy, ha, va in _LABEL_SPOTS:
            label.set_position((dx, dy))
            label.set_horizontalalignment(ha)
            label.set_verticalalignment(va)
            box = label.get_window_extent()
            inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
            clash = sum(_overlap(box, other) for other in placed) + (0.0 if inside else box.width * box.height)
            if not _alone(i, points, label_anchor(label), box):
                clash += 4.0 * box.width * box.height
            if best is None or clash < best[0]:
                best = (clash, dx, dy, ha, va, box)
            if clash == 0.0:
                break
        _, dx, dy, ha, va, box = best
        label.set_position((dx, dy))
        label.set_horizontalalignment(ha)
        label.set_verticalalignment(va)
        placed.append(box)


def label_anchor(label):
    """Where annotation ``label`` is attached, in display pixels: its point plus its offset in points."""
    x, y = label.axes.transData.transform(label.xy)
    dx, dy = label.get_position()
    scale = label.figure.dpi / 72.0
    return x + dx * scale, y + dy * scale


def _alone(i, points, anchor, box):
    """True when ``anchor`` and ``box``'s middle are nearest ``points[i]`` and the box holds no other point."""
    middle = ((box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2)
    for spot in (anchor, middle):
        distances = [(spot[0] - px) ** 2 + (spot[1] - py) ** 2 for px, py in points]
        if min(range(len(points)), key=distances.__getitem__) != i:
            return False
    return not any(j != i and box.x0 <= px <= box.x1 and box.y0 <= py <= box.y1 for j, (px, py) in enumerate(points))


def _overlap(a, b):
    """Area shared by boxes ``a`` and ``b`` (display units squared)."""
    return max(0.0, min(a.x1, b.x1) - max(a.x0, b.x0)) * max(0.0, min(a.y1, b.y1) - max(a.y0, b.y0))


def _say(ax, message):
    ax.text(0.5, 0.5, message, transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax.set_xticks([])
    ax.set_yticks([])
