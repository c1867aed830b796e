"""Every record the session log (events.jsonl) holds, made here, and the checks of a logged field.

A record is a JSON object with a ``type``; ``SessionLog.append`` stamps it
(``seq``, ``mono``, ``wall``) and ``SessionRunner.log`` puts the trial's
``step``, ``task`` (and ``practice``) in front. The constructors below fix
each kind's keys and their order, which is what the file holds byte for byte
(tests/live/test_event_records_golden.py). The task types fill the
``knob`` and ``response`` records with their own fields (after the keys made
here: ``studyapp.experiment.tasks``); ``response_problem`` checks the fields
every response shares before export reads it.

Checks. Every number has an upper bound as well: a value such as step 10^30
or F_max 10^308 is valid JSON but no session writes it, and letting it
through gave an overflow or a memory error further on (issue 21, item 14).
"""

import math

from studyapp.model.limits import FMAX_LIMIT

STEP_MAX = 10**6  # a session's steps: a few hundred
TRIAL_MAX = 10_000  # trials of one task per condition (the protocol allows 100 plus practice)
FMAX_MAX = FMAX_LIMIT  # N: no loop ran above it

SESSION_CREATED = "session_created"
SESSION_END = "session_end"
NOTE = "note"
ENGINE_NOTE = "one real-time engine per session: its seed, not the trials' loop_seed, seeds the sensor noise"


# the session and its runs -------------------------------------------------------------------------
def session_created(description: dict) -> dict:
    return {"type": SESSION_CREATED, "description": description}


def session_end(recovered: bool = False) -> dict:
    """The session's last trial has its response (``recovered``: written when a later open found it missing)."""
    return {"type": SESSION_END, "recovered": True} if recovered else {"type": SESSION_END}


def run_start(resume: bool, app_version: str, finished_trials: int, trials: int) -> dict:
    return {"type": "run_start", "resume": resume, "app_version": app_version, "finished_trials": finished_trials,
            "trials": trials}


def run_stop(reason: str) -> dict:
    return {"type": "run_stop", "reason": reason}


def log_repaired(dropped_bytes: int, copy: str) -> dict:
    return {"type": "log_repaired", "dropped_bytes": dropped_bytes, "copy": copy}


def log_damaged(lines: list, copy: str) -> dict:
    return {"type": "log_damaged", "lines": lines, "copy": copy}


def note(text: str) -> dict:
    return {"type": NOTE, "text": text, "by": "experimenter"}


# the live apparatus --------------------------------------------------------------------------------
def engine(info: dict, seed: int) -> dict:
    """A session's engine came up (``info``: ``Engine.info``); the metadata of its recording (audio.wav, ...).

    On a device on a link, ``device``: its ``info`` (link_device.LinkDevice.info: name, serial, calibration,
    latency, measured round trip); without one the key is left out (the simulated device).
    """
    record = {"type": "engine", "rate": info["rate"], "block": info["block"], "audio": info["audio"],
              "midi": info["midi"], "paced": info["paced"], "realtime": info["realtime"], "seed": seed,
              "note": ENGINE_NOTE}
    if info.get("device"):
        record["device"] = info["device"]
    return record


def device_health(trial: int, health: dict, totals: dict) -> dict:
    """A link device's frame counts over the engine's trial ``trial`` and since its link opened (DeviceHealth)."""
    return {"type": "device_health", "trial": trial, "health": dict(health), "totals": dict(totals)}


def engine_failed(faults: list) -> dict:
    return {"type": "engine_failed", "faults": faults}


def volume(db: float, gain: float) -> dict:
    return {"type": "volume", "db": db, "gain": gain}


def mute(on: bool) -> dict:
    return {"type": "mute", "on": on}


def pause() -> dict:
    return {"type": "pause"}


def resume() -> dict:
    return {"type": "resume"}


def abort(reason: str | None = None) -> dict:
    return {"type": "abort"} if reason is None else {"type": "abort", "reason": reason}


def emergency_stop(by: str = "operator", fault: str | None = None) -> dict:
    """The force stopped: by the ``operator`` or the ``participant``, or by a ``fault`` the engine latched (its text)."""
    return {"type": "emergency_stop", "by": by} if fault is None else {"type": "emergency_stop", "by": by,
                                                                       "fault": fault}


def rig_change(before: dict, now: dict, accepted: bool = True) -> dict:
    """A session resumed on another device than its last engine run's (session.json's ``device`` form)."""
    return {"type": "rig_change", "before": before, "now": now, "accepted": accepted}


def emergency_clear() -> dict:
    return {"type": "emergency_clear"}


# a trial ---------------------------------------------------------------------------------------------
def trial_start(trial: int, condition, conditions: list, restart: bool, restored_knobs: int,
                loop_seed: int) -> dict:
    return {"type": "trial_start", "trial": trial, "condition": condition, "conditions": conditions,
            "restart": restart, "restored_knobs": restored_knobs, "loop_seed": loop_seed}


def gesture(name: str, previous: str, reason: str | None = None) -> dict:
    record = {"type": "gesture", "name": name, "from": previous}
    return record if reason is None else {**record, "reason": reason}


def bowing(on: bool) -> dict:
    return {"type": "bowing", "on": on}


def stability(broken: bool, score: float, fmax: float) -> dict:
    return {"type": "stability", "broken": broken, "score": score, "fmax": fmax}


def fault(message: str, fmax: float) -> dict:
    return {"type": "fault", "message": message, "fmax": fmax}


def hand_trace(trial: int, spacing_s: float, t: list, x_mm: list, bow: list) -> dict:
    return {"type": "hand_trace", "trial": trial, "spacing_s": spacing_s, "t": t, "x_mm": x_mm, "bow": bow}


def pickup(control: str, trial: int, when: float | None, ignored: int) -> dict:
    """A knob acted after waiting for pickup: ``when`` (the trial's clock, s), ``ignored`` messages."""
    return {"type": "pickup", "control": control, "trial": trial, "when": when, "ignored": ignored}


def late_control(control: str, value: int) -> dict:
    """A control the worker applied in an attempt that had ended (an emergency stop, a restart) before its
    report came back: ``value`` the knob's step (0..127) or 1 for a pad. Logged so that no force the worker
    set goes unrecorded, and given to no task (a resumed rating restores only ``knob`` records)."""
    return {"type": "late_control", "control": control, "value": value}


def press_too_soon(control: str, since: float) -> dict:
    """The participant's press on a page shown ``since`` s ago, taken as the second press of a double press."""
    return {"type": "acknowledge", "by": "participant", "control": control, "accepted": False,
            "reason": f"pressed {since:.2f} s after the page appeared: taken as a double press"}


# what a participant did, as a task type logs it ----------------------------------------------------

def knob(index: int, value: int, **task_fields) -> dict:
    """Knob ``index`` turned to ``value`` (0..127), with the task's reading of it (its F_max, its condition)."""
    return {"type": "knob", "index": index, "value": value, **task_fields}


def pad(index: int) -> dict:
    return {"type": "pad", "index": index}


def acknowledge(by: str) -> dict:
    return {"type": "acknowledge", "by": by}


def response(task: str, **answer) -> dict:
    """A trial's answer: the task's fields after the ``task`` (``response_problem`` checks the shared ones)."""
    return {"type": "response", "task": task, **answer}


def knob_latency(controls: int, midi: int, median: float, largest: float) -> dict:
    return {"type": "knob_latency", "controls": controls, "midi": midi, "median": median, "max": largest}


def trial_health(trial: int, deadline_misses: int, underruns: int, faults: int, events_dropped: int,
                 limited: int) -> dict:
    """The engine's fault counters while a trial ran (``underruns``: the audio underruns; ``limited``: the
    output samples the limiter bent)."""
    return {"type": "trial_health", "trial": trial, "deadline_misses": deadline_misses, "underruns": underruns,
            "faults": faults, "events_dropped": events_dropped, "limited": limited}


# checks of a logged field ------------------------------------------------------------------------------
def integer(value, low, high=math.inf):
    """An int (not a bool) from ``low`` to ``high``."""
    return isinstance(value, int) and not isinstance(value, bool) and low <= value <= high


def number(value, high=math.inf):
    """A finite int or float (not a bool) from 0 to ``high``."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
            and 0 <= value <= high)


def text(value):
    """A non-blank string."""
    return isinstance(value, str) and value.strip() != ""


def response_problem(event, task_types):
    """None for a well-formed ``response`` record, else the problem as ``field = value: allowed ...``.

    A log line can be valid JSON and still not be a response the tasks wrote (an
    edited file, another program's line). Fields every response has: ``step`` an
    integer from 0 to ``STEP_MAX``, ``task`` one of ``task_types`` (name -> task
    type), ``trial`` an integer from 1 to ``TRIAL_MAX``, ``fmax`` a number from 0
    to ``FMAX_MAX`` (N), ``wall`` the time as text, ``practice`` and ``simulated`` (when
    present) true or false; the rest is the task type's (its ``response_problem``).
    """
    if not isinstance(event, dict):
        return f"event {event!r}: allowed is a JSON object"
    names = tuple(task_types)
    checks = [
        ("step", integer(event.get("step"), 0, STEP_MAX), f"an integer from 0 to {STEP_MAX}"),
        ("task", isinstance(event.get("task"), str) and event.get("task") in names, ", ".join(names)),
        ("trial", integer(event.get("trial"), 1, TRIAL_MAX), f"an integer from 1 to {TRIAL_MAX}"),
        ("fmax", number(event.get("fmax"), FMAX_MAX), f"a number from 0 to {FMAX_MAX:g} (N)"),
        ("wall", text(event.get("wall")), "the time as ISO-8601 text"),
        ("practice", isinstance(event.get("practice", False), bool), "true or false (absent: false)"),
        ("simulated", isinstance(event.get("simulated", False), bool), "true or false (absent: as session.json)"),
    ]
    for name, ok, allowed in checks:
        if not ok:
            return f"{name} = {event.get(name)!r}: allowed is {allowed}"
    return task_types[event["task"]].response_problem(event)
