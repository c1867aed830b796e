"""Export every response under a results folder as one tidy, long-format table.

One row per response, first the columns of the "Study results" contract:

    participant, session, task, condition, trial, fmax, rating, time, protocol_hash

then ``study, step, value, knob, peak_fmax, duration, app_version``.

- ``task`` names the task type; ``trial``, ``fmax``, ``time``, ``step`` and
  ``duration`` come from the response event, the rest from the task type's
  ``export_rows`` (``studyapp.experiment.tasks``):
- Rating rows: ``rating`` is the noisiness normalised to [0, 1] per
  participant (0 = their best, least noisy condition, the highest knob; 1 =
  their worst, the lowest knob), as the task logged it (``tasks/rating.py``);
  ``fmax`` the rating task's constant F_max (N); ``trial`` 1; ``value`` the
  raw knob position (0..127) and ``knob`` the knob that played the condition.
- Adjustment rows: ``fmax`` the confirmed breakdown F_max (N); ``rating``
  empty; ``trial`` 1..6 (per condition); ``value`` the knob position;
  ``peak_fmax`` the highest F_max reached in the trial.
- Listen rows: ``fmax`` the F_max played (N), ``duration`` how long; ``rating``
  and ``value`` empty.
- ``time`` is the ISO-8601 wall time of the response (the confirm).

Incomplete sessions are exported too: every confirmed response is data. The
CSV (``studyapp export``) reads as is in pandas and R; empty cells are missing.
"""

import json
from pathlib import Path

import pandas as pd

from studyapp.errors import InputDataError, UserError
from studyapp.experiment import response_event
from studyapp.experiment.session import EVENTS_FILE, SESSION_FILE
from studyapp.experiment.session_log import read_events
from studyapp.experiment.tasks import task_type

COLUMNS = ["participant", "session", "task", "condition", "trial", "fmax", "rating", "time", "protocol_hash",
           "study", "step", "value", "knob", "peak_fmax", "duration", "app_version"]


def _session_rows(folder):
    path = folder / SESSION_FILE
    try:
        info = json.loads(path.read_text(encoding="utf-8"))
        common = {
            "participant": info["participant"],
            "session": info["session"],
            "protocol_hash": info["protocol"]["sha256"],
            "study": info["study"],
            "app_version": info["app_version"],
        }
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputDataError(f"{path}: not a readable session file ({exc})") from None
    rows = []
    for event in read_events(folder / EVENTS_FILE):
        if isinstance(event, dict) and event.get("type") != "response":
            continue
        wrong = response_event.problem(event)
        if wrong is not None:
            seq = event.get("seq") if isinstance(event, dict) else "?"
            raise InputDataError(f"{folder / EVENTS_FILE}: response event seq {seq}: {wrong}")
        base = {**common, "task": event["task"], "trial": event["trial"], "fmax": event["fmax"],
                "time": event["wall"], "step": event["step"], "duration": event.get("duration")}
        rows += [{**base, **row} for row in task_type(event["task"]).export_rows(event)]
    return rows


def export_responses(results_dir):
    """A DataFrame of every response under ``results_dir`` (any level of the results layout)."""
    root = Path(results_dir)
    if not root.is_dir():
        raise UserError(f"{root}: no such results folder")
    rows = []
    for path in sorted(root.rglob(SESSION_FILE)):
        rows.extend(_session_rows(path.parent))
    frame = pd.DataFrame(rows, columns=COLUMNS)
    frame = frame.sort_values(["study", "participant", "session", "step", "knob"], kind="stable")
    frame["trial"] = frame["trial"].astype("int64")
    frame["step"] = frame["step"].astype("int64")
    frame["knob"] = frame["knob"].astype("Int64")
    frame["value"] = frame["value"].astype("Int64")  # empty for a task without a knob answer
    return frame.reset_index(drop=True)


def write_responses(results_dir, output):
    """Write ``export_responses(results_dir)`` to the CSV file ``output`` atomically; return the frame."""
    from studyapp.atomic import atomic_open

    frame = export_responses(results_dir)
    if frame.empty:
        raise UserError(f"{results_dir}: no responses found (no {SESSION_FILE} with confirmed responses)")
    with atomic_open(output, newline="", encoding="utf-8") as f:
        frame.to_csv(f, index=False)
    return frame
