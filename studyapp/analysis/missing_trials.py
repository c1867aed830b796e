"""Which participant lacks which responses: reported, never silently dropped.

A session that was aborted, a trial never confirmed, or a participant who did
only one task leaves holes. The statistics use every response that exists;
this check says what is absent, so a reader can judge the medians.

Expected counts, per task and condition: the number given by the caller (from
the protocol, e.g. 6 adjustment trials as in the paper), or else the most any
participant has, and at least the highest trial number seen. Every participant
who appears anywhere in the responses is expected in every condition of every
task present. A limitation follows: a trial missing for every participant at
once cannot be seen without the protocol's count.
"""

import numpy as np
import pandas as pd

from studyapp.analysis.responses import MEASURED_TASKS, response_values

MISSING_COLUMNS = ["participant", "task", "condition", "expected", "present", "missing_trials"]


def find_missing_trials(responses, expected=None):
    """DataFrame ``MISSING_COLUMNS``, one row per participant, task and condition short of responses.

    ``expected`` maps a task name to the number of responses each participant
    owes per condition (e.g. ``{"adjustment": 6}``); tasks not in it are
    inferred as the module docstring says. ``missing_trials`` lists the absent
    trial numbers separated by ';' (empty when the numbers are unknown).
    """
    expected = dict(expected or {})
    participants = sorted(responses["participant"].unique())
    rows = []
    for task in MEASURED_TASKS:
        conditions = sorted(responses.loc[responses["task"] == task, "condition"].unique())
        if not conditions:
            continue
        values = response_values(responses, task)
        for condition in conditions:
            done = values[values["condition"] == condition]
            counts = done.groupby("participant").size()
            want = expected.get(task)
            if want is None:
                highest = done["trial"].max()
                want = int(max(counts.max() if len(counts) else 0, 0 if np.isnan(highest) else highest))
            for participant in participants:
                mine = done[done["participant"] == participant]
                if len(mine) >= want:
                    continue
                have = set(mine["trial"].dropna().astype(int))
                absent = [str(t) for t in range(1, want + 1) if t not in have]
                rows.append((participant, task, condition, want, len(mine), ";".join(absent)))
    table = pd.DataFrame(rows, columns=MISSING_COLUMNS)
    for column in ["participant", "task", "condition", "missing_trials"]:
        table[column] = table[column].astype(object)
    return table


def describe_missing(row):
    """One line for a row of the missing-trials table."""
    absent = row.missing_trials.split(";") if row.missing_trials else []
    which = f" (missing trial{'s' if len(absent) > 1 else ''} {', '.join(absent)})" if absent else ""
    return (
        f"participant {row.participant} has {row.present} of {row.expected} {row.task} "
        f"responses for {row.condition}{which}"
    )
