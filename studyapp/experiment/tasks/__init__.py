"""The registry of task types: the one place a task type is named.

Each module named in ``MODULES`` is a task type (``studyapp.experiment.task_type``)
exposing ``TASK_TYPE``; its ``name`` is the protocol table, the value of
``[study] tasks`` and the ``task`` of its trials, events and exported rows.
The order here is the order in which messages list the tasks. Adding a task
type is one new module here plus its name in ``MODULES``. A task type with
``protocol_table = False`` (``page``) is a step the schedule makes, not a
table of the protocol.
"""

import importlib

MODULES = ("rating", "adjustment", "listen", "page")

TASK_TYPES = {t.name: t for t in (importlib.import_module(f"{__name__}.{m}").TASK_TYPE for m in MODULES)}


def task_names():
    return tuple(TASK_TYPES)


def protocol_task_names():
    """The task types a protocol names in ``[study] tasks`` (not ``page``: the schedule makes page steps)."""
    return tuple(name for name, t in TASK_TYPES.items() if getattr(t, "protocol_table", True))


def task_type(name):
    """The registered task type called ``name``; ValueError naming the allowed ones otherwise."""
    try:
        return TASK_TYPES[name]
    except (KeyError, TypeError):
        raise ValueError(f"task {name!r}: allowed is one of {', '.join(TASK_TYPES)}") from None
