"""Load and check the study's responses: an exported responses.csv or a results folder.

The export contract (``studyapp export``) gives one row per response with at
least ``participant, session, task, condition, trial, fmax, rating, time,
protocol_hash``. ``task`` names a registered task type
(``studyapp.experiment.tasks``), whose ``measure`` says which column holds
its outcome and the range allowed: ``rating`` (``rating`` is the
participant's noisiness in [0, 1], higher = noisier; ``fmax`` the task's
constant F_max) or ``adjustment`` (``fmax`` the confirmed breakdown F_max in
newtons, ``trial`` 1..6). Rows of a task without a measure (``listen``) are
checked and carried, but not analysed. The analysis needs ``participant,
task, condition, trial, fmax, rating``.

Practice trials (a ``practice`` column that is True, ``studyapp export``)
are left out before anything is checked or counted, unless
``include_practice``: the paper's statistics are of the real trials only. An
export without the column (older versions) has no practice rows. Likewise
the sessions of the simulated participant (a ``simulated`` column that is
True) are left out unless ``include_simulated``: an in-silico pilot is not a
participant. When nothing else is left, that is one line naming the option.

A response whose value is empty (a trial begun but never confirmed) is kept
out of the statistics but not forgotten: the missing-trials check counts it as
missing. A value that is present but not a number, out of range, or a task that
is not registered is bad input: one line naming the file, the column and the
row.
"""

import io
from pathlib import Path

import numpy as np
import pandas as pd

from studyapp.errors import InputDataError, UserError
from studyapp.experiment.export import export_responses
from studyapp.experiment.records import TRIAL_MAX
from studyapp.experiment.tasks import task_names, task_type
from studyapp.io.small_files import read_bytes

REQUIRED_COLUMNS = ["participant", "task", "condition", "trial", "fmax", "rating"]
TASKS = task_names()
MEASURED_TASKS = tuple(t for t in TASKS if task_type(t).measure is not None)
RESPONSES_LIMIT = 1 << 28  # bytes: a study's export is well under a megabyte
_TEXT_COLUMNS = ["participant", "session", "task", "condition", "protocol_hash"]


def load_responses(source, problems=None, include_practice=False, include_simulated=False):
    """Checked responses from ``source``: a ``.csv`` export or a results folder (practice rows left
    out unless ``include_practice``, simulated participants' unless ``include_simulated``).

    Returns ``(responses, label)``; ``label`` names the source in messages. A
    results folder is exported with ``studyapp.experiment.export.export_responses``,
    which appends to ``problems`` (a list) one line per session it skipped or log
    line it left out; without ``problems`` the first of them is an error.
    """
    path = Path(source)
    if path.suffix.lower() == ".csv":
        if not path.exists():
            raise InputDataError(f"{path}: no such responses file")
        data = read_bytes(path, "responses CSV", RESPONSES_LIMIT)  # a FIFO, a device, a sparse or huge file: refused
        try:
            frame = pd.read_csv(io.BytesIO(data), dtype={c: str for c in _TEXT_COLUMNS}, keep_default_na=True)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
            raise InputDataError(f"{path}: not a readable CSV file ({_first_line(exc)})") from None
        return check_responses(frame, str(path), csv_rows=True, include_practice=include_practice,
                               include_simulated=include_simulated), str(path)
    if path.is_dir():
        return check_responses(export_responses(path, problems), str(path),
                               include_practice=include_practice, include_simulated=include_simulated), str(path)
    raise UserError(f"{path}: expected a results folder or an exported responses .csv file")


def check_responses(frame, label, csv_rows=False, include_practice=False, include_simulated=False):
    """A cleaned copy of ``frame``: text columns as str, numbers as float, tasks checked.

    ``csv_rows`` numbers rows as lines of the CSV file (header = line 1) in messages.
    Practice rows are left out unless ``include_practice``; simulated participants' rows
    unless ``include_simulated``.
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in frame.columns]
    if missing:
        raise InputDataError(
            f"{label}: missing column '{missing[0]}' (the analysis needs {', '.join(REQUIRED_COLUMNS)})"
        )
    if len(frame) == 0:
        where = "the file has a header but no rows" if csv_rows else "no session in it holds a response"
        raise InputDataError(f"{label}: no responses ({where})")

    def where(index):
        return f"line {index + 2}" if csv_rows else f"row {index + 1}"

    frame = frame.reset_index(drop=True)
    if "practice" in frame.columns:
        practice = _flags(frame["practice"], "practice", label, where)
        if not include_practice:
            # the original line numbers stay in the index for the messages below
            frame = frame[~practice]
            if len(frame) == 0:
                raise InputDataError(f"{label}: no responses but practice ones (allowed: --include-practice)")
        frame = frame.assign(practice=practice[frame.index])
    left_out = []
    if "simulated" in frame.columns:
        simulated = _flags(frame["simulated"], "simulated", label, where)
        if not include_simulated:
            left_out = sorted({str(p) for p in frame.loc[simulated, "participant"]})
            frame = frame[~simulated]
            if len(frame) == 0:
                raise InputDataError(f"{label}: every response is from a simulated participant "
                                     f"({', '.join(left_out)}): allowed is --include-simulated to analyse them")
        frame = frame.assign(simulated=simulated[frame.index])
    frame = frame.copy()

    for column in ["participant", "task", "condition"]:
        text = frame[column].astype(object).where(frame[column].notna(), None)
        text = text.map(lambda v: None if v is None else str(v).strip())
        empty = text.isna() | (text == "")
        if empty.any():
            raise InputDataError(f"{label}: column '{column}' is empty at {where(_first(empty))}")
        frame[column] = text.astype(object)
    frame["task"] = frame["task"].str.lower()
    bad_task = ~frame["task"].isin(TASKS)
    if bad_task.any():
        i = _first(bad_task)
        raise InputDataError(
            f"{label}: column 'task' at {where(i)} is '{frame['task'][i]}'; allowed: {', '.join(TASKS)}"
        )
    frame["condition"] = frame["condition"].str.upper()
    if "session" in frame.columns:
        frame["session"] = frame["session"].astype(object).where(frame["session"].notna(), "").map(str)
    else:
        frame["session"] = ""

    for column in ["trial", "fmax", "rating"]:
        frame[column] = _numbers(frame[column], column, label, where)
    trials = frame["trial"].dropna()
    bad_trial = (trials < 1) | (trials > TRIAL_MAX) | (trials != np.round(trials))  # 1e12 would be a MemoryError
    if bad_trial.any():
        i = int(bad_trial.index[np.flatnonzero(bad_trial)[0]])
        raise InputDataError(f"{label}: column 'trial' at {where(i)} is {frame['trial'][i]:g}; "
                             f"allowed: 1, 2, 3, ... {TRIAL_MAX}")
    for task in MEASURED_TASKS:
        measure = task_type(task).measure
        values = frame[measure.column].where(frame["task"] == task)
        bad = values.notna() & ~(np.isfinite(values) & (values >= measure.low) & (values <= measure.high))
        if bad.any():
            i = _first(bad)
            raise InputDataError(
                f"{label}: column '{measure.column}' at {where(i)} is {values[i]:g}; allowed: {measure.allowed}"
            )
    frame = frame.reset_index(drop=True)
    frame.attrs["simulated_left_out"] = left_out  # participant IDs, for the report (set last: attrs are fragile)
    return frame


def response_values(responses, task):
    """The rows of ``task`` that hold a value, with that value (its measure's column) in a column ``value``."""
    column = task_type(task).measure.column
    rows = responses[(responses["task"] == task) & responses[column].notna()]
    return rows.assign(value=rows[column].astype(float))


def _numbers(series, column, label, where):
    """``series`` as float; an empty cell is NaN, anything else that is not a number is an error."""
    if pd.api.types.is_numeric_dtype(series) and not pd.api.types.is_bool_dtype(series):
        return series.astype(float)
    text = series.astype(object).map(lambda v: "" if v is None or (isinstance(v, float) and np.isnan(v)) else str(v).strip())
    numbers = pd.to_numeric(text.replace("", np.nan), errors="coerce")
    bad = numbers.isna() & (text != "")
    if bad.any():
        i = _first(bad)
        raise InputDataError(f"{label}: column '{column}' at {where(i)} is '{text[i]}', not a number")
    return numbers.astype(float)


def _first(mask):
    """The index label of the first True of ``mask`` (labels are the rows' places in the source)."""
    return int(mask.index[np.flatnonzero(mask.to_numpy())[0]])


def _flags(series, column, label, where):
    """A True/False ``column`` (``practice``, ``simulated``) as bool (a CSV's text too); empty is False."""
    def flag(v):
        if isinstance(v, (bool, np.bool_)):
            return bool(v)
        if v is None or (isinstance(v, float) and np.isnan(v)):
            return False
        return {"true": True, "false": False, "": False}.get(str(v).strip().lower())

    flags = series.map(flag)
    bad = flags.isna()
    if bad.any():
        i = _first(bad)
        raise InputDataError(f"{label}: column '{column}' at {where(i)} is '{series[i]}'; allowed: True, False")
    return flags.astype(bool)


def _first_line(exc):
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
