"""perceptual.png/.svg: each estimator's audio distance beside its delay-corrected error.

Two panels of horizontal bars sharing one row per estimator, ordered by audio
distance (closest to the ideal sensor's sound on top): left, ``audio_distance``
(perceptual_scores.py, against TRUE in the loop); right, the median
delay-corrected error E as percent of LOWPASS (eqs. 22-24, Fig. 5's measure).
The title gives Spearman's rank correlation between the two, the question the
paper's Sec. 9.2 asked of E and the noisiness ratings. An estimator whose loop
faulted has no bar and is marked in its row's label.
"""

import numpy as np

from studyapp.evaluation.figures import _pyplot, save


def draw(names, distances, errors, spearman=None):
    """The figure (not saved): ``distances`` and ``errors`` are name -> number."""
    plt = _pyplot()
    order = sorted(names, key=lambda n: (not np.isfinite(distances[n]), distances[n], names.index(n)))
    rows = np.arange(len(order))[::-1]
    fig, (left, right) = plt.subplots(1, 2, sharey=True, figsize=(9.0, 1.2 + 0.32 * len(order)))
    for ax, values, colour in ((left, distances, "#8fb8de"), (right, errors, "#d9a05b")):
        finite = [(y, values[n]) for y, n in zip(rows, order) if np.isfinite(values[n])]
        if finite:
            ax.barh([y for y, _ in finite], [v for _, v in finite], color=colour, edgecolor="#1f3b57", height=0.65)
        ax.grid(axis="x", alpha=0.3)
        low, high = ax.get_xlim()
        # Only the ticks inside the limits: the locator's others are not drawn but still hold labels.
        ax.set_xticks([t for t in ax.get_xticks() if low <= t <= high])
        ax.set_xlim(low, high)
    labels = [n if np.isfinite(distances[n]) else f"{n} (loop faulted)" for n in order]
    left.set_yticks(rows, labels, fontsize=8)
    left.set_xlabel("audio distance to TRUE in the loop (0 = same sound)")
    right.set_xlabel("median error E (% of LOWPASS)")
    right.axvline(100.0, color="0.6", lw=0.8, ls="--")
    right.tick_params(axis="y", left=False)
    title = "How the string sounds with each estimator in the loop, beside its error"
    if spearman is not None and spearman.get("rho") is not None:
        title += (f"\nSpearman rank correlation of the two: rho = {spearman['rho']:.2f} "
                  f"(n = {spearman['n']}, p = {spearman['p']:.2g})")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(w_pad=2.0)
    return fig


def perceptual_plot(names, distances, errors, stem, spearman=None):
    """Draw and write ``stem``.png and ``stem``.svg; return both paths."""
    plt = _pyplot()
    fig = draw(names, distances, errors, spearman)
    paths = save(fig, stem)
    plt.close(fig)
    return paths
