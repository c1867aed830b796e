"""The shape of a ``response`` event in events.jsonl, checked before it becomes a row of the export.

A log line can be valid JSON and still not be a response the tasks wrote (an
edited file, another program's line): a missing field, a text where a number
belongs, an unknown task. ``problem(event)`` names the first such field, so the
reader can stop with one line naming the file, the event and the field, rather
than with a ``KeyError`` deep in pandas. Fields (``studyapp.experiment.tasks``,
what each task type's ``export_rows`` reads): ``step`` an integer >= 0,
``task`` a registered task, ``trial`` an integer >= 1, ``fmax`` a finite
number >= 0 (N), ``wall`` the time as text; a rating's ``responses``, each
with ``condition``, ``knob``, ``value`` and ``rating``; any other task's
``condition``, and an adjustment's knob ``value``.
"""

import math

from studyapp.experiment.tasks import task_names


def _integer(value, low):
    return isinstance(value, int) and not isinstance(value, bool) and value >= low


def _number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value >= 0


def _text(value):
    return isinstance(value, str) and value.strip() != ""


def problem(event):
    """None for a well-formed response event, else the problem as ``field = value: allowed ...``."""
    if not isinstance(event, dict):
        return f"event {event!r}: allowed is a JSON object"
    checks = [
        ("step", _integer(event.get("step"), 0), "an integer >= 0"),
        ("task", isinstance(event.get("task"), str) and event.get("task") in task_names(), ", ".join(task_names())),
        ("trial", _integer(event.get("trial"), 1), "an integer >= 1"),
        ("fmax", _number(event.get("fmax")), "a finite number >= 0"),
        ("wall", _text(event.get("wall")), "the time as ISO-8601 text"),
    ]
    if event.get("task") != "rating":
        checks.append(("condition", _text(event.get("condition")), "an estimator name"))
    if event.get("task") == "adjustment":
        checks.append(("value", _integer(event.get("value"), 0), "a knob position, an integer >= 0"))
    for name, ok, allowed in checks:
        if not ok:
            return f"{name} = {event.get(name)!r}: allowed is {allowed}"
    if event["task"] == "rating":
        return _rating_problem(event.get("responses"))
    return None


def _rating_problem(responses):
    allowed = "a list of {condition, knob, value, rating} objects"
    if not isinstance(responses, list) or not responses or not all(isinstance(r, dict) for r in responses):
        return f"responses = {responses!r}: allowed is {allowed}"
    for r in responses:
        if not (_text(r.get("condition")) and _integer(r.get("knob"), 0) and _integer(r.get("value"), 0)
                and _number(r.get("rating"))):
            return f"responses item {r!r}: allowed is {allowed}"
    return None
