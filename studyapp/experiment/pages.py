"""The pages a participant reads between trials: the protocol's ``[[pages]]`` and the generated ones.

The paper's participants were welcomed, had the headphone level set, read
each task's instructions and tried a few training trials before the real
ones (Sec. 8.2). A protocol lists its pages as an array of tables:

    [[pages]]
    kind = "welcome"          # welcome, instructions, transition, break, goodbye or calibration
    title = "Welcome"         # optional (a default per kind)
    text = \"\"\"Markdown ...\"\"\"

- ``instructions`` names its ``task``; a ``transition`` may name the task it
  leads into, and a ``break`` the task whose breaks it is (without ``task``:
  every transition, every break);
- ``calibration`` is the headphone level check: a reference tone of
  ``tone_hz`` (20 .. 20000 Hz) at ``level_dbfs`` (-60 .. -18 dB re full
  scale, peak: -18 dBFS is the output limiter's knee, engine/signal_chain.py);
  without ``level_dbfs`` the tone is as loud as the stimulus (its RMS the
  bowed string's typical RMS at the protocol's F_max, computed from the model
  when the schedule is made and stated in the page's ``note``, which only the
  experimenter's console shows: ``level_check``; the participant's page never
  speaks of dBFS or F_max). The experimenter confirms it, not the participant.

Pages are Markdown: single line breaks (a TOML triple-quoted string's) join
into one paragraph, a blank line starts another.

The schedule (``schedule.build_schedule``) places them: welcome and
calibration pages first, each task's transition (from the second task on)
and instructions pages before its trials, goodbye pages last. When the
protocol has ``[[pages]]``, a task without an instructions page gets one
made of its table's ``instructions``, and a task after the first without a
transition page gets "Part k of n". Break pages (after every ``break_every``
real trials) and the "practice is over" page are made whenever a task asks
for them; a protocol without ``[[pages]]`` gets no other page. Every page of
the schedule is stored whole in session.json, so a resumed session shows the
same text whatever the protocol file says.
"""

import textwrap
from dataclasses import asdict, dataclass, replace

from studyapp.errors import UserError
from studyapp.experiment.fields import Fields

KINDS = ("welcome", "instructions", "transition", "break", "goodbye", "calibration")
WHO = ("participant", "experimenter")
TONE_HZ = (20.0, 20000.0)
LEVEL_DBFS = (-60.0, -18.0)  # peak; the top is the output limiter's knee (a level check is never bent)
TITLES = {"welcome": "Welcome", "instructions": "Instructions", "transition": "Next part", "break": "Break",
          "goodbye": "Thank you", "calibration": "Headphone level"}
BREAK_TEXT = "Take a short break. Press Continue when you are ready to go on."
PRACTICE_OVER = ("Practice is over", "That was the practice. The real trials start now.")


@dataclass(frozen=True)
class Page:
    kind: str
    text: str
    title: str
    task: str | None = None
    tone_hz: float | None = None
    level_dbfs: float | None = None
    pad: int = 0  # the pad that acknowledges it (the confirm pad of the task it belongs to)
    note: str = ""  # for the experimenter only (the level check's computed level): never on the participant's page

    @property
    def by(self):
        """Who acknowledges it: the experimenter for the headphone level check, else the participant."""
        return "experimenter" if self.kind == "calibration" else "participant"

    def to_dict(self):
        return asdict(self)

    @classmethod
    def from_dict(cls, d):
        return cls(kind=d["kind"], text=d["text"], title=d["title"], task=d.get("task"),
                   tone_hz=d.get("tone_hz"), level_dbfs=d.get("level_dbfs"), pad=int(d.get("pad", 0)),
                   note=str(d.get("note", "")))


def markdown(text):
    """A TOML string as Markdown: its common indentation removed (4 spaces would make a code block)."""
    return textwrap.dedent(text).strip()


def parse_pages(source, document, tasks):
    """The protocol's ``[[pages]]`` as ``Page``s, in file order; ``UserError`` (one line) if one is invalid."""
    value = document.get("pages", [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise UserError(f"{source}: pages = {value!r}: allowed is an array of tables, each [[pages]] "
                        "with kind and text (see docs/experiment.md)")
    kinds_allowed = "one of " + ", ".join(KINDS)
    tasks_allowed = "one of the tasks: " + ", ".join(tasks)
    pages = []
    for i, values in enumerate(value):
        table = Fields(source, "pages", values, label=f"[[pages]] #{i + 1}")
        kind = table.string("kind", kinds_allowed)
        if kind not in KINDS:
            table.fail("kind", f"= {kind!r}", kinds_allowed)
        text = markdown(table.string("text", "a non-empty Markdown text"))
        title = table.string("title", default=TITLES[kind])
        task = tone = level = None
        if kind in ("instructions", "transition", "break") and (kind == "instructions" or "task" in values):
            task = table.string("task", tasks_allowed)
            if task not in tasks:
                table.fail("task", f"= {task!r}", tasks_allowed)
            if kind == "transition" and task == tasks[0]:
                later = ", ".join(tasks[1:]) or "none, with one task"
                table.fail("task", f"= {task!r}", f"a task after the first (a transition leads into it): {later}")
        if kind == "calibration":
            tone = table.number("tone_hz", *TONE_HZ, "Hz")
            # without it, the stimulus's level (level_check.calibrated, when the schedule is made)
            level = table.number("level_dbfs", *LEVEL_DBFS, "dBFS") if "level_dbfs" in values else None
        table.finish()
        pages.append(Page(kind, text, title, task, tone, level))
    return tuple(pages)


def transition_page(pages, task, k, n, pad):
    """The page leading into the k-th of n tasks (k >= 2): the protocol's for it, its generic one, or made."""
    for wanted in (task, None):
        found = [p for p in pages if p.kind == "transition" and p.task == wanted]
        if found:
            return [replace(p, task=task, pad=pad) for p in found]
    return [Page("transition", f"Part {k - 1} is over: thank you! Take a moment if you like.\n\n"
                 f"Press Continue for the instructions of part {k}.", f"Part {k} of {n}", task, pad=pad)]


def instructions_pages(pages, task, instructions, k, n, pad):
    """The instructions pages of ``task`` (the k-th of n): the protocol's, or made of its ``instructions``."""
    found = [replace(p, pad=pad) for p in pages if p.kind == "instructions" and p.task == task]
    title = f"Part {k} of {n}: instructions" if n > 1 else "Instructions"
    return found or [Page("instructions", markdown(instructions), title, task, pad=pad)]


def break_page(pages, task, done, total, pad):
    """The break after ``done`` of ``total`` real trials of ``task``: the protocol's text (or a default) and how far."""
    found = [p for p in pages if p.kind == "break" and p.task == task] or [
        p for p in pages if p.kind == "break" and p.task is None]
    page = found[0] if found else Page("break", BREAK_TEXT, TITLES["break"])
    return replace(page, task=task, pad=pad, text=f"{page.text}\n\n{done} of {total} trials of this part are done.")


def practice_over_page(task, pad):
    title, text = PRACTICE_OVER
    return Page("transition", text, title, task, pad=pad)


def pages_of(pages, kind, pad):
    return [replace(p, pad=pad) for p in pages if p.kind == kind]
