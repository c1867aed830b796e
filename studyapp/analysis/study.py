"""The whole analysis of a study's responses (paper Sec. 9-10), as one result object.

Adjustment task (Fig. 7): every confirmed breakdown F_max is one sample of its
condition; conditions are ordered best first (highest median). Rating task
(Fig. 8): every participant's normalised noisiness is one sample; ordered best
first (lowest median). For each task: median and quartiles, the paper's
pairwise Wilcoxon rank-sum tests of every pair on the samples pooled across
participants (optionally Holm-corrected; trials of one participant are not
independent, so these p-values are too small), and the within-subject
analysis on per-participant medians: Friedman's test and Holm-corrected
pairwise signed-rank tests with effect sizes (within_subject.py). The compact
letters marking which conditions differ (``letters``, drawn on Figs. 7-8)
come from the within-subject tests: two conditions get no common letter when
Friedman's test rejects and their Holm-corrected signed-rank p is below alpha
(``WithinSubject.different_pairs``). The letters of the pooled rank-sum tests
(``pooled_letters``) are kept for the report and drawn only on request
(``pooled_letters=True``, ``analyse --pooled-letters``), labelled as such.
Fig. 9 pairs the two medians per condition.
Consistency and, given an evaluation, the numerical and perceptual
comparisons follow (consistency.py, numerical.py, perceptual.py).
"""

from dataclasses import dataclass

import numpy as np
import pandas as pd

from studyapp.stats.compact_letters import compact_letters
from studyapp.analysis.consistency import participant_spearman, variance_decomposition
from studyapp.analysis.missing_trials import describe_missing, find_missing_trials
from studyapp.analysis.numerical import compare_with_numerical
from studyapp.analysis.perceptual import perceptual_correlation
from studyapp.analysis.rank_sum import pairwise_rank_sum
from studyapp.analysis.responses import response_values
from studyapp.analysis.summary import summarise
from studyapp.analysis.within_subject import WithinSubject, friedman_table, within_subject
from studyapp.experiment.tasks import task_type

ALPHA = 0.05


@dataclass
class TaskAnalysis:
    """One task's samples and statistics, conditions ordered best first."""

    task: str
    groups: dict  # condition -> float array of samples, best first
    summary: pd.DataFrame  # condition, n, median, q1, q3
    wilcoxon: pd.DataFrame  # condition_a, condition_b, statistic, p_value, significant, p_raw
    letters: dict  # condition -> compact letters of the within-subject tests
    within: WithinSubject  # per-participant medians, Friedman, pairwise signed-rank tests
    pooled_letters: dict  # condition -> compact letters of the pooled rank-sum tests (the paper's)

    @property
    def conditions(self):
        return list(self.groups)

    def medians(self):
        return self.summary.set_index("condition")["median"]


@dataclass
class StudyAnalysis:
    """Everything the report shows; built by ``analyse``."""

    source: str
    responses: pd.DataFrame
    adjustment: TaskAnalysis
    rating: TaskAnalysis
    missing: pd.DataFrame
    participant_spearman: pd.DataFrame  # participant, rho, p_value, conditions
    spearman_task: str  # the task the per-participant rho is computed on
    variance: pd.DataFrame
    numerical: pd.DataFrame | None = None
    perceptual: pd.DataFrame | None = None  # noisiness against audio_distance and error (perceptual.py)
    perceptual_note: str | None = None  # why the perceptual row is empty, when it is
    holm: bool = False
    alpha: float = ALPHA
    pooled_letters: bool = False  # Figs. 7-8 show the pooled rank-sum letters instead of the within-subject ones
    include_simulated: bool = False  # the simulated participants' sessions are analysed too
    simulated_left_out: tuple = ()  # the simulated participants left out (participant IDs)

    def figure_letters(self, task):
        """(letters drawn on ``task``'s figure, what they come from): within-subject unless ``pooled_letters``."""
        if self.pooled_letters:
            return task.pooled_letters, "pooled"
        return task.letters, "within"

    @property
    def participants(self):
        return sorted(self.responses["participant"].unique())

    def protocol_hashes(self):
        """The distinct protocol hashes of the responses (more than one: a mixed study)."""
        if "protocol_hash" not in self.responses:
            return []
        return sorted(set(self.responses["protocol_hash"].dropna().astype(str)) - {""})

    def warnings(self):
        """Lines a reader must see before trusting the numbers: missing responses, mixed protocols."""
        lines = [describe_missing(row) for row in self.missing.itertuples()]
        hashes = self.protocol_hashes()
        if len(hashes) > 1:
            lines.append(f"the responses come from {len(hashes)} different protocols (protocol_hash)")
        return lines

    def sample_size_warnings(self):
        """Lines on what the number of participants allows the within-subject tests (within_subject.py)."""
        return [
            f"{task.task}: {line}"
            for task in (self.adjustment, self.rating)
            for line in task.within.warnings(self.alpha)
        ]

    def friedman(self):
        """DataFrame ``task, statistic, p_value, n_participants``: Friedman's test of each task."""
        return friedman_table([(task.task, task.within) for task in (self.adjustment, self.rating)])

    def intra_lower_pct(self):
        """Mean over conditions of how much lower intra- than total variance is, in percent."""
        values = self.variance["intra_lower_pct"].to_numpy(dtype=float)
        values = values[np.isfinite(values)]
        return float(values.mean()) if values.size else float("nan")


def analyse(responses, source="responses", evaluation=None, holm=False, alpha=ALPHA, expected=None,
            pooled_letters=False, include_simulated=False):
    """``StudyAnalysis`` of checked ``responses`` (see responses.py).

    ``evaluation`` is a parsed evaluation.json or None; ``expected`` maps a task
    to its responses per condition and participant (see missing_trials.py).
    ``pooled_letters`` draws the pooled rank-sum letters on Figs. 7-8;
    ``include_simulated`` records that simulated participants were kept.
    """
    adjustment_values = response_values(responses, "adjustment")
    rating_values = response_values(responses, "rating")
    adjustment = _task(adjustment_values, "adjustment", holm=holm, alpha=alpha)
    rating = _task(rating_values, "rating", holm=holm, alpha=alpha)
    spearman_task, spearman_values = ("adjustment", adjustment_values)
    if adjustment_values.empty:
        spearman_task, spearman_values = ("rating", rating_values)
    numerical = perceptual = perceptual_note = None
    if evaluation is not None:
        numerical = compare_with_numerical(evaluation, rating.medians(), adjustment.medians())
        perceptual, perceptual_note = perceptual_correlation(evaluation, rating.medians())
    return StudyAnalysis(
        source=source,
        responses=responses,
        adjustment=adjustment,
        rating=rating,
        missing=find_missing_trials(responses, expected),
        participant_spearman=participant_spearman(spearman_values),
        spearman_task=spearman_task,
        variance=variance_decomposition(adjustment_values, adjustment.conditions),
        numerical=numerical,
        perceptual=perceptual,
        perceptual_note=perceptual_note,
        holm=holm,
        alpha=alpha,
        pooled_letters=pooled_letters,
        include_simulated=include_simulated,
        simulated_left_out=tuple(responses.attrs.get("simulated_left_out", ())),
    )


def _task(values, task, holm, alpha):
    higher_is_better = task_type(task).measure.higher_is_better
    medians = values.groupby("condition")["value"].median()
    # Best first; ties broken by name so the order is reproducible.
    order = sorted(medians.index, key=lambda c: (-medians[c] if higher_is_better else medians[c], c))
    groups = {c: values.loc[values["condition"] == c, "value"].to_numpy(dtype=float) for c in order}
    wilcoxon = pairwise_rank_sum(groups, alpha=alpha, holm=holm)
    pooled = wilcoxon.loc[wilcoxon["significant"], ["condition_a", "condition_b"]].itertuples(index=False)
    within = within_subject(values, order, alpha)
    return TaskAnalysis(task, groups, summarise(groups), wilcoxon,
                        letters=compact_letters(order, within.different_pairs(alpha)), within=within,
                        pooled_letters=compact_letters(order, [tuple(pair) for pair in pooled]))
