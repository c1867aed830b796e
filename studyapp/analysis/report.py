"""One self-contained ``report.html``: every table and figure of the analysis.

Figures are embedded as base64 PNG (``data:`` URIs), so the file can be mailed
or archived alone and opens in any browser without the folder beside it.
``tables_html`` gives the same tables without figures, for the GUI.
"""

import base64
import html
import math

import numpy as np

from studyapp import __version__
from studyapp.analysis.counted import counted
from studyapp.analysis.missing_trials import describe_missing
from studyapp.analysis.rank_sum import POOLED
from studyapp.stats.signed_rank import EXACT_LIMIT
from studyapp.experiment.tasks import task_type

_STYLE = """
body { font-family: sans-serif; max-width: 60em; margin: 1em auto; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.5em; text-align: right; }
th { background: #eee; }
td.name, th.name { text-align: left; }
td.sig { background: #f4b8a8; }
td.same { background: #d6e8d0; }
td.self { background: #ddd; }
p.warn { color: #a33; }
img { max-width: 100%; }
"""

_CAPTIONS = {
    "fig7_adjustment": "Fig. 7. Maximum friction force F_max at which the string breaks down, per condition.",
    "fig8_rating": "Fig. 8. Subjective noisiness ratings, normalised per participant.",
    "fig9_scatter": "Fig. 9. Median noisiness against median max F_max; conditions near the top left are better.",
}


def report_html(study, figures):
    """The report as one HTML string; ``figures`` maps a figure name to its PNG bytes."""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        "<title>studyapp analysis</title>",
        f"<style>{_STYLE}</style></head><body>",
        "<h1>Study analysis</h1>",
        _inputs(study),
        _missing(study),
        "<h2>Adjustment task: maximum F<sub>max</sub></h2>",
        _figure(figures, "fig7_adjustment"),
        _task_tables(study, study.adjustment, "N"),
        "<h2>Rating task: noisiness</h2>",
        _figure(figures, "fig8_rating"),
        _task_tables(study, study.rating, ""),
        "<h2>Noisiness against F<sub>max</sub></h2>",
        _figure(figures, "fig9_scatter"),
        _consistency(study),
        _numerical(study),
        f'<p style="color:#888;font-size:0.8em">studyapp {html.escape(__version__)}</p>',
        "</body></html>",
    ]
    return "\n".join(p for p in parts if p)


def tables_html(study):
    """Every table of the report, without figures (for a Qt text view)."""
    parts = [
        _inputs(study),
        _missing(study),
        "<h2>Adjustment task: maximum F<sub>max</sub></h2>",
        _task_tables(study, study.adjustment, "N"),
        "<h2>Rating task: noisiness</h2>",
        _task_tables(study, study.rating, ""),
        _consistency(study),
        _numerical(study),
    ]
    return f"<html><head><style>{_STYLE}</style></head><body>" + "\n".join(p for p in parts if p) + "</body></html>"


def _inputs(study):
    responses = study.responses
    correction = "Holm-corrected p-values" if study.holm else "uncorrected p-values (as the paper)"
    items = [
        f"Source: <code>{html.escape(study.source)}</code>",
        f"{counted(len(study.participants), 'participant')}: {html.escape(', '.join(study.participants))}",
        f"{len(responses)} responses ({(responses['task'] == 'adjustment').sum()} adjustment, "
        f"{(responses['task'] == 'rating').sum()} rating)",
        f"The paper's pairwise Wilcoxon rank-sum tests (normal approximation with tie correction), "
        f"{POOLED}, {correction}",
        "Within-subject tests on each participant's median per condition: Friedman's test across conditions "
        "and pairwise Wilcoxon signed-rank tests, Holm-corrected, with the matched-pairs rank-biserial "
        "correlation as effect size",
        f"Significance at p &lt; {study.alpha:g}",
        "Letters on Figs. 7-8: " + ("the pooled rank-sum tests', on request (<code>--pooled-letters</code>)"
                                    if study.pooled_letters else "the within-subject tests'"),
    ]
    if study.simulated_left_out:
        items.append(f"Left out: {counted(len(study.simulated_left_out), 'simulated participant')} "
                     f"({html.escape(', '.join(study.simulated_left_out))}); "
                     "<code>--include-simulated</code> analyses them too")
    if study.include_simulated:
        simulated = _simulated_participants(study)
        items.append(f'<span class="warn">Simulated participants included (--include-simulated): '
                     f"{html.escape(', '.join(simulated)) or 'none present'} ({len(simulated)} of "
                     f"{counted(len(study.participants), 'participant')} simulated)</span>")
    hashes = study.protocol_hashes()
    if len(hashes) > 1:
        items.append(f'<span class="warn">The responses come from {len(hashes)} different protocols</span>')
    return "<h2>Inputs</h2><ul>" + "".join(f"<li>{item}</li>" for item in items) + "</ul>"


def _simulated_participants(study):
    responses = study.responses
    if "simulated" not in responses:
        return []
    return sorted({str(p) for p in responses.loc[responses["simulated"].astype(bool), "participant"]})


def _missing(study):
    if study.missing.empty:
        return "<h2>Missing trials</h2><p>None: every participant has every expected response.</p>"
    lines = "".join(f"<li>{html.escape(describe_missing(row))}</li>" for row in study.missing.itertuples())
    return (
        "<h2>Missing trials</h2>"
        f'<p class="warn">Responses are missing ({len(study.missing)} participant, task and condition '
        "combinations). Every response that exists is included in every statistic.</p>"
        f"<ul>{lines}</ul>"
    )


def _task_tables(study, task, unit):
    if not task.groups:
        return f"<p>No {task.task} responses.</p>"
    unit_text = f" ({unit})" if unit else ""
    pooled = study.pooled_letters
    summary = _table(
        ["condition", "n", f"median{unit_text}", "q1", "q3", "letters (within-subject)",
         *(["letters (pooled rank-sum)"] if pooled else [])],
        [
            [row.condition, row.n, row.median, row.q1, row.q3, task.letters[row.condition],
             *([task.pooled_letters[row.condition]] if pooled else [])]
            for row in task.summary.itertuples()
        ],
    )
    drawn = "the pooled rank-sum letters (on request)" if pooled else "the within-subject letters"
    return (
        f"<h3>Summary (best first)</h3>"
        "<p>Conditions sharing a letter do not differ. Within-subject letters: Friedman's test rejects and the "
        f"pair's Holm-corrected signed-rank p &lt; {study.alpha:g} (tests below). The figure shows {drawn}.</p>"
        f"{summary}"
        f"<h3>Pairwise Wilcoxon rank-sum p-values, {POOLED}</h3>"
        "<p>The paper's test (Figs. 7-8): every response counts as an independent sample, but the responses "
        "of one participant are not independent of each other, so these p-values are too small; the "
        "within-subject tests below treat participants as the units. "
        f"Shaded red: p &lt; {study.alpha:g}, the distributions differ; green: no significant difference.</p>"
        f"{_significance_matrix(task)}"
        f"{_within_subject(study, task, unit_text)}"
    )


def _within_subject(study, task, unit_text):
    within = task.within
    warnings = "".join(f'<p class="warn">{html.escape(line)}</p>' for line in within.warnings(study.alpha))
    medians = _table(
        ["participant"] + [str(c) for c in within.medians.columns],
        [[participant, *row] for participant, row in zip(within.medians.index, within.medians.to_numpy())],
    )
    f = within.friedman
    friedman = _table(["participants", "conditions", "chi-square", "p"],
                      [[f.n_participants, f.n_conditions, f.statistic, f.p_value]])
    pairs = _table(
        ["condition a", "condition b", "T = min(T+, T-)", "p", "p (Holm)", "effect size r", "significant"],
        [list(row) for row in within.signed_rank.itertuples(index=False)],
    )
    return (
        f"<h3>Within-subject tests: each participant's median per condition{unit_text}</h3>"
        f"{warnings}{medians}"
        "<h4>Friedman test across conditions</h4>"
        "<p>Each participant is one block; chi-square approximation with tie correction "
        "(<code>scipy.stats.friedmanchisquare</code>). A small p: the conditions are not all alike.</p>"
        f"{friedman}"
        "<h4>Pairwise Wilcoxon signed-rank tests, Holm-corrected</h4>"
        "<p>Paired by participant; zero differences dropped (<code>zero_method=\"wilcox\"</code>); exact "
        "p-values over every sign assignment to the ranks (ties included), the normal approximation beyond "
        f"{EXACT_LIMIT} participants. Effect size: matched-pairs "
        "rank-biserial correlation r = (T+ &minus; T&minus;) / (T+ + T&minus;) (Kerby 2014), positive when "
        f"condition a is larger. Significant: p (Holm) &lt; {study.alpha:g}.</p>"
        f"{pairs}"
    )


def _significance_matrix(task):
    names = task.conditions
    cell = {}
    for row in task.wilcoxon.itertuples():
        cell[(row.condition_a, row.condition_b)] = cell[(row.condition_b, row.condition_a)] = row
    head = "".join(f"<th>{html.escape(n)}</th>" for n in names)
    body = []
    for a in names:
        cells = []
        for b in names:
            if a == b:
                cells.append('<td class="self"></td>')
                continue
            row = cell[(a, b)]
            cells.append(f'<td class="{"sig" if row.significant else "same"}">{_format(row.p_value)}</td>')
        body.append(f'<tr><th class="name">{html.escape(a)}</th>{"".join(cells)}</tr>')
    return f'<table><tr><th class="name"></th>{head}</tr>{"".join(body)}</table>'


def _consistency(study):
    task = task_type(study.spearman_task).measure.label
    table = _table(
        ["participant", "rho", "p", "conditions"],
        [[r.participant, r.rho, r.p_value, r.conditions] for r in study.participant_spearman.itertuples()],
    )
    parts = [
        "<h2>Consistency</h2>",
        f"<h3>Each participant's ranking against the global ranking ({task}, Spearman)</h3>",
        "<p>The paper found rho &gt; 0.9 for every participant. rho is undefined (&ndash;) with fewer than "
        "three conditions, or when the participant's medians or the global medians are all equal.</p>",
        table,
    ]
    if not study.variance.empty:
        headline = intra_variance_headline(study.intra_lower_pct())
        parts += [
            "<h3>Intra- against inter-subject variance of max F<sub>max</sub> (N<sup>2</sup>)</h3>",
            f"<p>{headline} (the paper: 61% lower). Intra-subject variance needs two or more trials "
            "per participant and condition.</p>",
            _table(
                ["condition", "participants", "intra", "inter", "total", "intra lower by (%; < 0: higher)"],
                [list(r[1:]) for r in study.variance.itertuples()],
            ),
        ]
    return "\n".join(parts)


def intra_variance_headline(lower_pct):
    """The consistency headline for intra-subject variance ``lower_pct`` percent below the total."""
    if not math.isfinite(lower_pct):
        return "Intra-subject variance cannot be computed here"
    shown = f"{abs(lower_pct):.0f}"
    if shown == "0":
        return "Intra-subject variance is on average <b>about equal to</b> the total variance of Fig. 7"
    word = "lower" if lower_pct > 0 else "higher"
    return f"Intra-subject variance is on average <b>{shown}%</b> {word} than the total variance of Fig. 7"


def _numerical(study):
    if study.numerical is None:
        return ""
    rows = [
        [r.comparison, r.metric, r.n, r.rho, r.p_value, r.conditions] for r in study.numerical.itertuples()
    ]
    return (
        "<h2>Against the numerical evaluation</h2>"
        "<p>Spearman rho between subjective and numerical rankings, oriented so that rho &gt; 0 means they "
        "agree (the paper: 0.61 for noisiness against error, 0.43 for F<sub>max</sub> against delay).</p>"
        + _table(["comparison", "numerical metric", "n", "rho", "p", "conditions"], rows)
        + _perceptual(study)
    )


def _perceptual(study):
    if study.perceptual is None:
        return ""
    note = f'<p class="warn">{html.escape(study.perceptual_note)}</p>' if study.perceptual_note else ""
    rows = [
        [r.comparison, r.metric, r.n, r.rho, r.p_value, r.paper_rho, r.conditions]
        for r in study.perceptual.itertuples()
    ]
    return (
        "<h3>Noisiness against the perceptual audio distance</h3>"
        "<p>Spearman rho between the median normalised noisiness per condition and each estimator's "
        "<code>audio_distance</code> (its audio against the audio with the true velocity, "
        "<code>studyapp evaluate --perceptual</code>), beside noisiness against numerical error and the "
        "paper's 0.61. Both are better when lower, so rho &gt; 0 means the rankings agree.</p>"
        f"{note}"
        + _table(["comparison", "numerical metric", "n", "rho", "p", "paper rho", "conditions"], rows)
    )


def _figure(figures, name):
    png = figures.get(name)
    if png is None:
        return ""
    data = base64.b64encode(png).decode("ascii")
    caption = html.escape(_CAPTIONS[name])
    return f'<figure><img alt="{caption}" src="data:image/png;base64,{data}"><figcaption>{caption}</figcaption></figure>'


def _table(header, rows):
    head = "".join(f'<th class="{"name" if k == 0 else ""}">{html.escape(h)}</th>' for k, h in enumerate(header))
    body = []
    for row in rows:
        cells = "".join(
            f'<td class="name">{html.escape(str(v))}</td>' if k == 0 else f"<td>{_format(v)}</td>"
            for k, v in enumerate(row)
        )
        body.append(f"<tr>{cells}</tr>")
    return f"<table><tr>{head}</tr>{''.join(body)}</table>"


def _format(value):
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        if math.isnan(value):
            return "&ndash;"
        return f"{value:.3g}" if abs(value) < 1e-3 and value != 0 else f"{value:.3f}".rstrip("0").rstrip(".")
    return html.escape(str(value))
