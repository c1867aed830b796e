"""The within-subject analysis of one task: participants, not trials, as the independent units.

Every participant does every condition (paper Sec. 8.1), so conditions are
compared within participants:

1. each participant's median per condition: adjustment, the median of their
   trials' max F_max (six per condition in the paper); rating, their
   normalised noisiness (one per condition). A participant without any
   response in some condition is left out of these tests (each test needs a
   complete block) and named in the report;
2. Friedman's test across all conditions (friedman.py);
3. the Wilcoxon signed-rank test of every pair of conditions (signed_rank.py),
   Holm-corrected over the task's pairs (holm.py): ``significant`` is
   p_holm < alpha. ``effect_size`` is the matched-pairs rank-biserial
   correlation, positive when ``condition_a`` tends to be larger.

``different_pairs`` is what the compact letters of Figs. 7-8 show: the pairs
whose Holm-corrected signed-rank p is below alpha, provided Friedman's test
rejects first (with two conditions there is no omnibus test: the one pair's
test decides). Asking the omnibus test first is the usual protection; it
can only take pairs away, never add one.

``warnings`` says when there are too few participants for a test to mean
much: the Friedman chi-square below six participants, and the number of
participants the pairwise tests as used need: the exact two-sided
signed-rank p of n participants is at least 2^(1 - n) (every difference of
one sign), and Holm's correction over the task's m pairs multiplies the
smallest p by m, so no pair can be significant unless m 2^(1 - n) < alpha
(36 pairs at 0.05: 11 participants; 28 pairs: 11; one pair: 6).
"""

from dataclasses import dataclass
from itertools import combinations

import pandas as pd

from studyapp.analysis.counted import counted
from studyapp.stats.friedman import MIN_CONDITIONS, RELIABLE_PARTICIPANTS, Friedman, friedman_test
from studyapp.stats.friedman import minimum_p as friedman_minimum_p
from studyapp.stats.holm import holm_adjust
from studyapp.stats.signed_rank import minimum_p as signed_rank_minimum_p
from studyapp.stats.signed_rank import participants_needed, signed_rank_test

SIGNED_RANK_COLUMNS = ["condition_a", "condition_b", "statistic", "p_value", "p_holm", "effect_size", "significant"]
FRIEDMAN_COLUMNS = ["task", "statistic", "p_value", "n_participants"]


@dataclass
class WithinSubject:
    """One task's per-participant medians, Friedman test and pairwise signed-rank tests."""

    medians: pd.DataFrame  # index participant, one column per condition (task order); complete participants
    excluded: dict  # participant -> conditions they have no response in
    friedman: Friedman
    signed_rank: pd.DataFrame  # SIGNED_RANK_COLUMNS

    @property
    def n_participants(self):
        return len(self.medians)

    def warnings(self, alpha):
        """Lines on what these participants allow: too few for a test, participants left out."""
        lines = [
            f"{participant} is left out of the within-subject tests (no response for {', '.join(missing)})"
            for participant, missing in self.excluded.items()
        ]
        n, k = self.medians.shape
        if k < 2:
            return lines
        if n == 0:
            return lines + ["no participant has every condition: no within-subject tests"]
        if k < MIN_CONDITIONS:
            lines.append(f"Friedman's test needs {MIN_CONDITIONS} or more conditions (here {k})")
        elif n < RELIABLE_PARTICIPANTS:
            line = (f"Friedman's test with {counted(n, 'participant')}: its chi-square p is unreliable below "
                    f"{RELIABLE_PARTICIPANTS} participants, read it as a guide")
            smallest = friedman_minimum_p(n, k)
            if smallest >= alpha:
                line += f"; an exact test could not reach p < {alpha:g} either (smallest p (k!)^(1-n) = {smallest:.3g})"
            lines.append(line)
        pairs = k * (k - 1) // 2
        smallest = signed_rank_minimum_p(n)
        needed = participants_needed(alpha, pairs)
        if n >= needed:
            return lines
        if pairs == 1:
            lines.append(
                f"a signed-rank test on {counted(n, 'participant')} cannot reach p < {alpha:g} two-sided: the smallest "
                f"exact p is 2^(1-n) = {smallest:.3g}; {needed} participants are needed"
            )
        else:
            lines.append(
                f"no pair can be significant with {counted(n, 'participant')}: the smallest exact two-sided signed-rank p "
                f"is 2^(1-n) = {smallest:.3g}, and Holm's correction over the {pairs} pairs multiplies it by "
                f"{pairs}: {pairs * smallest:.3g}, not below {alpha:g}; {needed} participants are needed"
            )
        return lines

    def different_pairs(self, alpha):
        """The pairs the within-subject tests find different (module docstring), for the compact letters."""
        table = self.signed_rank
        if table.empty:
            return []
        f = self.friedman
        if f.n_conditions >= MIN_CONDITIONS and not f.p_value < alpha:  # NaN (not computed) rejects nothing
            return []
        rows = table.loc[table["significant"], ["condition_a", "condition_b"]].itertuples(index=False)
        return [tuple(row) for row in rows]


def participant_medians(values, conditions):
    """(participant x condition medians of complete participants, {participant: conditions missing}).

    ``values`` has columns ``participant, condition, value``; columns follow ``conditions``.
    """
    if values.empty or not conditions:
        return pd.DataFrame(columns=list(conditions), dtype=float), {}
    table = values.pivot_table(index="participant", columns="condition", values="value", aggfunc="median")
    table = table.reindex(columns=list(conditions)).sort_index()
    gaps = table.isna()
    excluded = {p: [c for c in conditions if gaps.loc[p, c]] for p in table.index[gaps.any(axis=1)]}
    complete = table[~gaps.any(axis=1)].astype(float)
    complete.index = complete.index.astype(object)
    complete.columns = complete.columns.astype(object)
    return complete, excluded


def within_subject(values, conditions, alpha=0.05):
    """``WithinSubject`` of one task's ``values`` (participant, condition, value), conditions in ``conditions`` order."""
    medians, excluded = participant_medians(values, conditions)
    rows = []
    if len(medians):
        for name_a, name_b in combinations(list(conditions), 2):
            test = signed_rank_test(medians[name_a].to_numpy(), medians[name_b].to_numpy())
            # one participant's sign is all a single pair has: r = +-1 says nothing, so it is not given
            effect = test.effect_size if len(medians) >= 2 else float("nan")
            rows.append((name_a, name_b, test.statistic, test.p_value, effect))
    table = pd.DataFrame(rows, columns=["condition_a", "condition_b", "statistic", "p_value", "effect_size"])
    for column in ("condition_a", "condition_b"):
        table[column] = table[column].astype(object)
    table["p_holm"] = holm_adjust(table["p_value"].to_numpy(dtype=float))
    table["significant"] = table["p_holm"] < alpha
    return WithinSubject(medians, excluded, friedman_test(medians.to_numpy(dtype=float)), table[SIGNED_RANK_COLUMNS])


def friedman_table(analyses):
    """DataFrame ``FRIEDMAN_COLUMNS``, one row per ``(task, WithinSubject)`` in ``analyses``."""
    rows = [(task, w.friedman.statistic, w.friedman.p_value, w.friedman.n_participants) for task, w in analyses]
    table = pd.DataFrame(rows, columns=FRIEDMAN_COLUMNS)
    table["task"] = table["task"].astype(object)
    return table
