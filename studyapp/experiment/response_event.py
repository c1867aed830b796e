"""The shape of a ``response`` event in events.jsonl, checked before it becomes a row of the export.

A log line can be valid JSON and still not be a response the tasks wrote (an
edited file, another program's line): a missing field, a text where a number
belongs, an unknown task. ``problem(event)`` names the first such field, so the
reader can stop with one line naming the file, the event and the field, rather
than with a ``KeyError`` deep in pandas. Fields common to every task: ``step``
an integer from 0 to ``STEP_MAX``, ``task`` a registered task, ``trial`` an integer from 1 to ``TRIAL_MAX``,
``fmax`` a number from 0 to ``FMAX_MAX`` (N, the loop's 200 N), ``wall`` the time as text, ``practice``
(when present) true or false; the rest is the
task type's (``response_problem`` in ``studyapp.experiment.tasks``).
"""

from studyapp.experiment.event_fields import FMAX_MAX, STEP_MAX, TRIAL_MAX, integer, number, text
from studyapp.experiment.tasks import task_names, task_type


def problem(event):
    """None for a well-formed response event, else the problem as ``field = value: allowed ...``."""
    if not isinstance(event, dict):
        return f"event {event!r}: allowed is a JSON object"
    checks = [
        ("step", integer(event.get("step"), 0, STEP_MAX), f"an integer from 0 to {STEP_MAX}"),
        ("task", isinstance(event.get("task"), str) and event.get("task") in task_names(), ", ".join(task_names())),
        ("trial", integer(event.get("trial"), 1, TRIAL_MAX), f"an integer from 1 to {TRIAL_MAX}"),
        ("fmax", number(event.get("fmax"), FMAX_MAX), f"a number from 0 to {FMAX_MAX:g} (N)"),
        ("wall", text(event.get("wall")), "the time as ISO-8601 text"),
        ("practice", isinstance(event.get("practice", False), bool), "true or false (absent: false)"),
    ]
    for name, ok, allowed in checks:
        if not ok:
            return f"{name} = {event.get(name)!r}: allowed is {allowed}"
    return task_type(event["task"]).response_problem(event)
