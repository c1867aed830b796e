"""The fields every task's table shares: practice, breaks, listening time, who bows.

The paper's participants were shown "a few training trials" before each task
and ran 55 trials in one sitting (Sec. 8.2). A protocol says, per task:

- ``practice``: trials before the real ones (0 .. 20, default 0), marked
  ``practice`` in the log and the export and left out of the analysis;
- ``break_every``: a break page after every N real trials (1 .. 1000), not
  after the last; left out, there are none (0 is refused: a break every 0
  trials means nothing);
- ``min_listen_s``: a confirm is accepted only once each condition of the
  trial has been heard that long (s, 0 .. 600, default 0) with the bow on and
  F_max above 0 (``confirm_pad.ConfirmPadTrial``); a task that is not
  confirmed (listen) has no such field;
- ``bow``: ``"participant"`` (default: the participant starts and stops
  bowing) or ``"auto"`` (the bow is put on the string at each trial's start).

Each task's spec inherits ``PhaseFields`` and its ``parse`` passes
``**read_phases(table)``, so the fields are read, checked and stored once.
"""

from dataclasses import asdict, dataclass

PRACTICE_MAX = 20
BREAK_EVERY_MAX = 1000
MIN_LISTEN_MAX = 600.0  # s
BOW_MODES = ("participant", "auto")


@dataclass(frozen=True, kw_only=True)
class PhaseFields:
    practice: int = 0
    break_every: int = 0
    min_listen_s: float = 0.0
    bow: str = "participant"


def read_phases(table, confirmed=True):
    """The phase fields of a task's protocol ``table``; ``confirmed``: the task has a confirm (min_listen_s)."""
    bow_allowed = "one of " + ", ".join(f'"{m}"' for m in BOW_MODES)
    bow = table.string("bow", bow_allowed, default="participant")
    if bow not in BOW_MODES:
        table.fail("bow", f"= {bow!r}", bow_allowed)
    fields = PhaseFields(
        practice=table.integer("practice", 0, PRACTICE_MAX, default=0),
        # "a break every 0 trials" means nothing: left out, there are none; given, it is 1 or more
        break_every=table.integer("break_every", 1, BREAK_EVERY_MAX) if "break_every" in table.values else 0,
        min_listen_s=(table.number("min_listen_s", 0.0, MIN_LISTEN_MAX, "s", default=0.0) if confirmed else 0.0),
        bow=bow,
    )
    return asdict(fields)
