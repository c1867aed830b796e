"""Figures of the evaluation: Fig. 5-style box plots and the speed/accuracy trade.

Fig. 5 (paper): for one group of recordings, three panels of box plots across
recordings, the per-recording objective, the error and the delay magnitude
|D| as percent of LOWPASS, each with its estimators ordered best (lowest
median) to worst (``panel_order``). The delay panel shows |D|, as the
objective counts it: a lead of the band-limited LVT is as much a mismatch as
a lag, so an estimator one sample ahead of the LVT is not better than one
in step with it.
Boxes of the best estimator and of those not significantly different from it
(Wilcoxon rank-sum, p >= 0.05) are filled; the others are hollow.

The trade (``studyapp tradeoff``): cost against F_g per rate with the Pareto
front (``tradeoff_figure``); per rate, median error against median delay with
cost as colour, the Pareto front of all three filled (``pareto_figure``); and
error, delay and CPU load against rate (``rate_figure``). Point labels are
placed by ``labels.place_labels``, so no two texts overlap.

Every figure is written as PNG and SVG (matplotlib, Agg backend).
"""

import numpy as np

from studyapp.evaluation.labels import place_labels
from studyapp.evaluation.significance import not_different_from_best
from studyapp.io.atomic import atomic_path

PANELS = (
    ("objective", "objective per recording"),
    ("error_pct_lowpass", "error E (% of LOWPASS)"),
    ("abs_delay_pct_lowpass", "delay |D| (% of LOWPASS)"),
)


def _null_formatter():
    from matplotlib.ticker import NullFormatter

    return NullFormatter()


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, stem):
    """Write ``stem``.png and ``stem``.svg atomically; return both paths."""
    paths = []
    for suffix in (".png", ".svg"):
        target = stem.with_suffix(suffix)
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format=suffix[1:], dpi=120, bbox_inches="tight")
        paths.append(target)
    return paths


def panel_order(samples):
    """(names best to worst by median, the best and those not significantly different from it)."""
    def median(name):
        return np.nanmedian(samples[name]) if np.isfinite(samples[name]).any() else np.inf

    return sorted(samples, key=median), not_different_from_best(samples)


def boxplots(measures, title, stem):
    """One Fig. 5-style figure: ``measures`` is measure -> name -> values."""
    plt = _pyplot()
    names = list(next(iter(measures.values())))
    fig, axes = plt.subplots(1, 3, figsize=(max(9.0, 1.25 * len(names)), 4.6))
    for ax, (key, label) in zip(axes, PANELS):
        samples = {n: np.asarray(measures[key][n], dtype=np.float64) for n in names}
        order, best = panel_order(samples)
        data = [samples[n][np.isfinite(samples[n])] for n in order]
        parts = ax.boxplot(data, patch_artist=True, widths=0.6, showfliers=True)
        for name, box in zip(order, parts["boxes"]):
            box.set_facecolor("#8fb8de" if name in best else "white")
            box.set_edgecolor("#1f3b57")
        for median in parts["medians"]:
            median.set_color("#b22222")
        ax.set_xticks(range(1, len(order) + 1), order, rotation=60, ha="right", fontsize=8)
        ax.set_title(label, fontsize=10)
        if key != "objective":
            ax.axhline(100.0, color="0.6", lw=0.8, ls="--")
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle(f"{title}  (filled: best and not significantly different, Wilcoxon rank-sum p >= 0.05)",
                 fontsize=10)
    fig.tight_layout()
    paths = save(fig, stem)
    plt.close(fig)
    return paths


def _available(table, rate=None):
    return [r for r in table if r["available"] and (rate is None or r["rate"] == rate)]


def tradeoff_figure(table):
    """Cost (ns/sample, streaming) against the global objective, one panel per rate, Pareto front drawn."""
    plt = _pyplot()
    rates = sorted({row["rate"] for row in table})
    fig, axes = plt.subplots(1, len(rates), figsize=(4.4 * len(rates), 4.4), squeeze=False)
    panels = []
    for ax, rate in zip(axes[0], rates):
        rows = [r for r in _available(table, rate) if np.isfinite(r["objective"])]
        for r in rows:
            ax.scatter(r["cost_ns_per_sample"], r["objective"], color="#1f77b4" if r["pareto"] else "0.6", s=22,
                       zorder=3)
        front = sorted((r for r in rows if r["pareto"]), key=lambda r: r["cost_ns_per_sample"])
        legend = None
        if front:
            ax.step([r["cost_ns_per_sample"] for r in front], [r["objective"] for r in front], where="post",
                    color="#1f77b4", lw=1.2, label="Pareto front", zorder=2)
            legend = ax.legend(fontsize=8, loc="upper right")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(_null_formatter())
        ax.margins(0.15)
        ax.set_xlabel("cost (ns/sample, streaming form)")
        ax.set_ylabel("global objective F_g (lower is better)")
        ax.set_title(f"{rate / 1000:g} kHz", fontsize=10)
        ax.grid(alpha=0.3)
        panels.append((ax, rows, legend))
    fig.tight_layout()
    for ax, rows, legend in panels:
        place_labels(ax, [(r["cost_ns_per_sample"], r["objective"]) for r in rows], [r["estimator"] for r in rows],
                     avoid=[legend] if legend is not None else ())
    return fig


def pareto_figure(table, rate):
    """One rate: median error against median delay (us, samples on top), colour = cost; filled = Pareto front.

    The front is that of three criteria, all lower is better: median error,
    median |delay| and cost (``pareto_error_delay_cost``).
    """
    from matplotlib.colors import LogNorm


    plt = _pyplot()
    rows = [r for r in _available(table, rate)
            if np.isfinite(r["error_median"]) and np.isfinite(r["delay_median_us"])]
    fig, ax = plt.subplots(figsize=(6.4, 5.0))
    if rows:
        costs = [r["cost_ns_per_sample"] for r in rows]
        low, high = min(costs), max(costs)
        norm = LogNorm(low / 1.5, high * 1.5) if high / low < 2.25 else LogNorm(low, high)
        cmap = plt.get_cmap("viridis")
        for r in rows:
            colour = cmap(norm(r["cost_ns_per_sample"]))
            on = r["pareto_error_delay_cost"]
            ax.scatter(r["delay_median_us"], r["error_median"], s=40, zorder=3, linewidths=1.5,
                       facecolors=colour if on else "white", edgecolors=colour)
        bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax)
        bar.set_label("cost (ns/sample, streaming form)")
        ax.set_yscale("log")
    else:
        ax.text(0.5, 0.5, "no estimator available at this rate", transform=ax.transAxes, ha="center")
    ax.margins(0.15)
    sample_us = 1e6 / rate
    low, high = ax.get_xlim()
    if high - low < 4 * sample_us:  # equal delays: show a few samples either side, not a sliver of one
        middle = (low + high) / 2
        ax.set_xlim(middle - 2 * sample_us, middle + 2 * sample_us)
    ax.set_xlabel("median delay D (us)")
    ax.set_ylabel("median error E (m/s)")
    top = ax.secondary_xaxis("top", functions=(lambda us: us * rate * 1e-6, lambda n: n / rate * 1e6))
    top.set_xlabel("median delay D (samples)")
    ax.set_title(f"{rate / 1000:g} kHz: filled = Pareto front of error, delay and cost", fontsize=10)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    if rows:
        place_labels(ax, [(r["delay_median_us"], r["error_median"]) for r in rows], [r["estimator"] for r in rows],
                     marker_px=5.0)
    return fig


def rate_figure(table):
    """What a higher rate buys: median error (m/s), median delay (us) and CPU load of each estimator against rate."""
    plt = _pyplot()
    table = _available(table)
    names = list(dict.fromkeys(row["estimator"] for row in table))
    rates_khz = sorted({row["rate"] / 1000 for row in table})
    colours = plt.get_cmap("tab20").colors
    markers = "osD^v<>ph*"
    fig, axes = plt.subplots(1, 3, figsize=(13.0, 4.2))
    for i, name in enumerate(names):
        rows = sorted((r for r in table if r["estimator"] == name), key=lambda r: r["rate"])
        rates = [r["rate"] / 1000 for r in rows]
        style = {"marker": markers[i % len(markers)], "color": colours[i % len(colours)], "label": name}
        axes[0].plot(rates, [r["error_median"] for r in rows], **style)
        axes[1].plot(rates, [r["delay_median_us"] for r in rows], **style)
        axes[2].plot(rates, [r["cost_ns_per_sample"] * r["rate"] * 1e-9 * 100 for r in rows], **style)
    axes[0].set_ylabel("median error E (m/s)")
    axes[1].set_ylabel("median delay D (us)")
    axes[2].set_ylabel("CPU load of one core (%)")
    for ax in axes:
        ax.set_xlabel("rate (kHz)")
        ax.set_xscale("log")
        ax.set_xticks(rates_khz, [f"{r:g}" for r in rates_khz])
        ax.minorticks_off()
        ax.grid(alpha=0.3)
    axes[0].set_yscale("log")
    axes[2].set_yscale("log")
    if names:
        axes[2].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return fig


def written(fig, stem):
    """Save ``fig`` as ``stem``.png/.svg, close it, and return both paths."""
    plt = _pyplot()
    paths = save(fig, stem)
    plt.close(fig)
    return paths
