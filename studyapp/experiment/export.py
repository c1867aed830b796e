"""Export every response under a results folder as one tidy, long-format table.

One row per response, first the columns of the "Study results" contract:

    participant, session, task, condition, trial, fmax, rating, time, protocol_hash

then ``study, step, practice, value, knob, peak_fmax, duration, app_version``,
the trial's engine health ``deadline_misses, underruns, faults,
events_dropped``, the session's ``experimenter, session_number,
order_row, simulated``, and the device the participant held ``device,
device_serial, device_latency_ms``.

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
- ``practice`` is True for a practice trial (its response logged with
  ``"practice": true``), False otherwise; the analysis leaves practice rows
  out by default.
- Pages (task ``page``) are not responses of the study: their
  acknowledgements stay in events.jsonl and make no row.
- ``time`` is the ISO-8601 wall time of the response (the confirm).
- ``deadline_misses``, ``underruns``, ``faults``, ``events_dropped``,
  ``limited``: what the real-time engine counted while the trial ran (the
  session's ``trial_health`` records of its step, summed over its attempts;
  ``limited``: the output samples the limiter bent, 0 for logs made before it
  was counted); empty for a session without a real-time engine (``studyapp run``).

- ``simulated``: True when the simulated participant gave the response: the
  response's own ``simulated`` (every response logged since issue 31 says who
  gave it), else, for older logs, the session's (``enrolment.is_simulated``:
  session.json's ``simulated``, or its ``apparatus.participant``); the
  analysis leaves these rows out by default (``studyapp analyse
  --include-simulated``).
- ``device``: ``simulated``, or the name a device on a link gave in its
  handshake; ``device_serial`` its serial number (empty on the simulated
  device); ``device_latency_ms`` the link's latency (the host's answer-ahead,
  ms; 0 on the simulated device). From the ``engine`` record of the run that
  answered (each engine run of a session logs one: a session resumed on another
  rig has each response's own), else session.json's ``device``; empty for
  a session stored before it was.
- ``experimenter``, ``session_number``, ``order_row``: from session.json
  (``session_info``); empty when not given, or for a session stored before
  they were. The experimenter's ``notes`` stay in session.json: free text of
  up to 2000 characters and several lines, they would repeat on every
  response row and break the table's one-line cells.

Incomplete sessions are exported too: every confirmed response is data. A
session that cannot be read is skipped, and a damaged line of a log left out
(the valid lines after it are kept); each is reported, naming the file and
line. The description comes from the log's CRC-checked ``session_created``
copy where there is one, a field session.json differs in reported
(``session_description``); a session in another participant's folder (a
copied folder) is exported under its own participant, with a warning (``studyapp export`` prints them as warnings, and with ``--strict``
refuses to write anything). A session whose folder was copied (the same
``session_created`` record in two folders) is counted once, the copy reported
(``session_identity``). A session whose log two programs wrote at once (a
step with two responses, a repeated ``seq``: ``written_twice``) is skipped the
same way: which answer counts cannot be told. A complete session is exported
whole whether or not its ``session_end`` was written. The
CSV (``studyapp export``) reads as is in pandas and R; empty cells are missing.
"""

from pathlib import Path

import pandas as pd

from studyapp.errors import InputDataError, UserError
from studyapp.experiment import records
from studyapp.experiment.enrolment import is_simulated
from studyapp.experiment.log_scan import written_twice
from studyapp.experiment.session import SIMULATED_DEVICE
from studyapp.experiment.session_description import read_description
from studyapp.experiment.session_files import EVENTS_FILE, SESSION_FILE
from studyapp.experiment.session_identity import counted_once
from studyapp.experiment.session_log import read_log
from studyapp.experiment.tasks import TASK_TYPES, task_type
from studyapp.experiment.trial_health import ADDED, HEALTH_COLUMNS
from studyapp.io.atomic import atomic_open

SESSION_COLUMNS = ["experimenter", "session_number", "order_row"]  # what session.json tells of the session
DEVICE_COLUMNS = ["device", "device_serial", "device_latency_ms"]  # session.json's ``device``
COLUMNS = ["participant", "session", "task", "condition", "trial", "fmax", "rating", "time", "protocol_hash",
           "study", "step", "practice", "value", "knob", "peak_fmax", "duration", "app_version", *HEALTH_COLUMNS,
           *SESSION_COLUMNS, "simulated", *DEVICE_COLUMNS]


def _session_rows(folder, problems):
    """The rows of one session; an unreadable session is skipped (a line in ``problems``).

    Damaged log lines are left out with a line in ``problems``; a valid line that is
    not a well-formed event is bad input (``InputDataError``).
    """
    path = folder / SESSION_FILE
    events_file = folder / EVENTS_FILE
    try:
        log = read_log(events_file)
    except (UserError, OSError) as exc:  # a folder, FIFO, device or a file over the limit: not a log
        reason = str(exc) if isinstance(exc, UserError) else f"{events_file}: {exc.strerror or exc}"
        problems.append(f"{folder}: skipped, {reason}")
        return []
    try:
        info, notes = read_description(folder, log)
        common = {
            "participant": info["participant"],
            "session": info["session"],
            "protocol_hash": info["protocol"]["sha256"],
            "study": info["study"],
            "app_version": info["app_version"],
            **{column: info.get(column) for column in SESSION_COLUMNS},
            "simulated": is_simulated(info),
            **device_columns(info.get("device")),
        }
    except UserError as exc:
        problems.append(f"{folder}: skipped, {exc}")
        return []
    except (KeyError, TypeError) as exc:
        problems.append(f"{folder}: skipped, {path}: not a readable session file (no {exc})")
        return []
    problems.extend(notes)
    if folder.parent.name != info["participant"]:
        problems.append(f"{folder}: a session of participant {info['participant']!r} (its log says so) in the "
                        f"folder of {folder.parent.name!r} (copied or renamed?): exported as {info['participant']!r}")
    problems.extend(log.messages(str(events_file)))
    if log.torn:
        problems.append(f"{events_file}: a torn last line ({len(log.torn)} bytes, never confirmed) left out")
    if log.malformed:
        number, _, raw = log.malformed[0]
        raise InputDataError(f"{events_file} line {number}: {raw.strip()[:40]!r} is not an event: "
                             "allowed is a JSON object with a 'type'")
    twice = written_twice(log)
    if twice:
        problems.append(f"{folder}: skipped, {events_file}: {twice}: two programs wrote this log at once, so "
                        "which answer counts cannot be told")
        return []
    health = _trial_health(log.events)
    rows = []
    held = {}  # the device of the engine run answering now (its ``engine`` record); before any, session.json's
    for event in log.events:
        if event.get("type") == "engine":
            held = engine_device_columns(event)
        if event.get("type") != "response":
            continue
        wrong = records.response_problem(event, TASK_TYPES)
        if wrong is not None:
            seq = event.get("seq") if isinstance(event, dict) else "?"
            raise InputDataError(f"{folder / EVENTS_FILE}: response event seq {seq}: {wrong}")
        base = {**common, "task": event["task"], "trial": event["trial"], "fmax": event["fmax"],
                "time": event["wall"], "step": event["step"], "duration": event.get("duration"),
                "practice": event.get("practice") is True,
                "simulated": event.get("simulated", common["simulated"]) is True}
        base.update(held)
        base.update(health.get(event["step"], {}))
        rows += [{**base, **row} for row in task_type(event["task"]).export_rows(event)]
    return rows


def engine_device_columns(engine):
    """The device columns of the responses an engine run answered: its ``engine`` record's ``device`` (a link
    device's handshake), or the simulated device when the record has none (issue 41, item 9: a session resumed on
    another rig was exported with the device it started on)."""
    device = engine.get("device")
    if isinstance(device, dict):
        return device_columns({"kind": "link", "info": device})
    return device_columns(dict(SIMULATED_DEVICE))


def device_columns(device):
    """``device`` (simulated, or the link device's name), ``device_serial``, ``device_latency_ms`` from
    session.json's ``device``; empty for a session stored before it was, or a link whose handshake it lacks."""
    empty = dict.fromkeys(DEVICE_COLUMNS)
    if not isinstance(device, dict):
        return empty
    if device.get("kind") == "simulated":
        return {**empty, "device": "simulated", "device_latency_ms": float(device.get("latency_ms", 0.0))}
    info = device.get("info")
    if not isinstance(info, dict):
        return {**empty, "device": device.get("kind")}
    return {"device": info.get("name"), "device_serial": info.get("serial"),
            "device_latency_ms": info.get("latency_ms")}


def _trial_health(events):
    """{step: {column: count}} from the ``trial_health`` records, summed over a step's attempts."""
    health = {}
    for event in events:
        if event.get("type") != "trial_health":
            continue
        counts = health.setdefault(event.get("step"), dict.fromkeys(HEALTH_COLUMNS, 0))
        for column in HEALTH_COLUMNS:
            value = event.get(column, 0 if column in ADDED else None)
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                seq = event.get("seq", "?")
                raise InputDataError(f"trial_health event seq {seq}: {column} = {value!r}: "
                                     "allowed is a whole number >= 0")
            counts[column] += value
    return health


def session_folders_under(root):
    """Every session folder at or below ``root`` (holding a session.json or an events.jsonl)."""
    return sorted({p.parent for name in (SESSION_FILE, EVENTS_FILE) for p in Path(root).rglob(name)})


def export_responses(results_dir, problems=None):
    """A DataFrame of every response under ``results_dir`` (any level of the results layout).

    A session that cannot be read is skipped, and a damaged line of a log left
    out; each is one line appended to ``problems`` (a list) naming the file.
    Without ``problems`` the first one raises ``InputDataError``. A malformed
    event (valid JSON, wrong fields) raises ``InputDataError`` either way.
    """
    root = Path(results_dir)
    if not root.is_dir():
        raise UserError(f"{root}: no such results folder")
    read, said = [], {}
    for folder in session_folders_under(root):
        said[folder] = []
        read.append((folder, _session_rows(folder, said[folder])))
    kept, copies = counted_once(read)  # a copied session folder counts once (session_identity)
    found = [line for folder, _ in kept for line in said[folder]] + copies
    rows = [row for _, session_rows in kept for row in session_rows]
    if found and problems is None:
        raise InputDataError(found[0])
    if problems is not None:
        problems.extend(found)
    frame = pd.DataFrame(rows, columns=COLUMNS)
    frame = frame.sort_values(["study", "participant", "session", "step", "knob"], kind="stable")
    frame["trial"] = frame["trial"].astype("int64")
    frame["practice"] = frame["practice"].astype(bool)
    frame["simulated"] = frame["simulated"].astype(bool)
    frame["step"] = frame["step"].astype("int64")
    frame["knob"] = frame["knob"].astype("Int64")
    frame["value"] = frame["value"].astype("Int64")  # empty for a task without a knob answer
    for column in [*HEALTH_COLUMNS, "session_number", "order_row"]:
        frame[column] = frame[column].astype("Int64")  # empty without a real-time engine, or when not stored
    return frame.reset_index(drop=True)


def save_responses(frame, results_dir, output):
    """Write the exported ``frame`` to the CSV file ``output`` atomically (refused when it is empty)."""
    if frame.empty:
        raise UserError(f"{results_dir}: no responses found (no {SESSION_FILE} with confirmed responses)")
    with atomic_open(output, newline="", encoding="utf-8") as f:
        frame.to_csv(f, index=False)
