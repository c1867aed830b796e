"""The participant's window in each state a session shows it, driven as the controller drives it.

Used by the offscreen tests and, run as ``python -m tests.gui.participant_states WxH ...``,
by the Xvfb screenshot test: for each size and state it prints one JSON line
with the layout problems and every visible text of the rendered window.
Trials are the real protocols' (sinclair2014's eight-condition rating and its
adjustment, the demo's three-condition rating), started by their task types.
Pages (``page-KIND``) are sinclair2014's own, as its schedule places them (the
longest of each kind), shown as the console shows them (``show_trial`` in the
page phase, then ``show_page``).
"""

import json
import sys
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.schedule import build_schedule
from studyapp.experiment.tasks import task_type
from studyapp.live.controller import instructions_for
from studyapp.live.evented import EventGroup

ROOT = Path(__file__).resolve().parents[2]
PAGE_KINDS = ("welcome", "calibration", "instructions", "transition", "break", "goodbye")
STATES = ("idle", "rating3", "rating8", "adjustment", "paused", "finished", *(f"page-{k}" for k in PAGE_KINDS))


class FakeController:
    """The controller's side the window sees: its events, the current trial's state, ``set_bowing``."""

    def __init__(self):
        self.events = EventGroup("trial", "bowing", "refused")
        self.runner = SimpleNamespace(task=None)
        self.protocol = None
        self.bowing_asked = []

    def set_bowing(self, on):
        self.bowing_asked.append(bool(on))
        self.events.bowing.emit(on=bool(on))

    def start(self, protocol, task, step=0, **spec_changes):
        """Start the participant's first trial of ``task`` as the controller does (its spec changed
        by ``spec_changes``); returns what the console shows."""
        protocol = load_protocol(ROOT / "protocols" / protocol)
        trials, _ = build_schedule(protocol, 0)
        trial = next(t for t in trials if t.task == task)
        spec = replace(protocol.task(task), **spec_changes)
        self.protocol = SimpleNamespace(specs={task: spec}, participant_title=protocol.participant_title)
        self.runner.task = task_type(task).start(spec, trial)
        shown = {"step": step, "total": len(trials), "instructions": instructions_for(protocol, task)}
        self.events.trial.emit(trial=trial, **shown)
        return shown


def longest_page(protocol, kind):
    """The schedule's step showing the longest page of ``kind`` in ``protocol``, and the schedule's length."""
    trials, _ = build_schedule(load_protocol(ROOT / "protocols" / protocol), 0)
    step = max((t for t in trials if t.page is not None and t.page.kind == kind), key=lambda t: len(t.page.text))
    return step, len(trials)


def put_in_state(window, controller, state):
    """Show ``state`` (one of ``STATES``) in ``window``, as the console would."""
    window.show_title("Bowing a virtual string")
    if state == "idle":
        window.show_state("idle")
        return
    if state.startswith("page-"):
        step, total = longest_page("sinclair2014.toml", state[len("page-"):])
        window.show_state("running")
        window.show_trial(step.step, total, "", "page", step.trial, None)
        window.show_page(step.page.kind, step.page.title, step.page.text, step.page.by)
        return
    trial = {"rating3": ("demo.toml", "rating"), "rating8": ("sinclair2014.toml", "rating"),
             "adjustment": ("sinclair2014.toml", "adjustment")}.get(state, ("sinclair2014.toml", "rating"))
    window.show_state("running")
    window.show_trial(**controller.start(*trial))
    for index in range(8):
        window.knobs.show_knob(index, 75)
    if state == "paused":
        window.show_state("paused")
    elif state == "finished":
        window.show_state("finished")


def visible_texts(window):
    from PySide6.QtWidgets import QAbstractButton, QLabel, QWidget

    texts = [window.windowTitle()]
    for widget in window.findChildren(QWidget):
        if widget.isVisibleTo(window) and isinstance(widget, (QLabel, QAbstractButton)):
            texts.append(widget.text())
        if widget.isVisibleTo(window) and widget.toolTip():
            texts.append(widget.toolTip())
    return [t for t in texts if t]


def render(size, state):
    from PySide6.QtWidgets import QApplication

    from tests.gui.layout_check import layout_problems
    from studyapp.gui.participant_window import ParticipantWindow

    app = QApplication.instance()
    controller = FakeController()
    window = ParticipantWindow(controller)
    window.setFixedSize(*size)
    window.show()
    put_in_state(window, controller, state)
    for _ in range(5):
        app.processEvents()
    result = {"size": list(size), "state": state, "problems": layout_problems(window),
              "texts": visible_texts(window), "dials": len(window.knobs.visible_knobs()),
              "page": window.page_view.isVisibleTo(window) and window.page_view.title.text(),
              "page_scrolls": window.page_view.text.verticalScrollBar().maximum() > 0,
              "image_size": [window.grab().width(), window.grab().height()]}
    window.close()
    return result


def main(argv):
    from PySide6.QtWidgets import QApplication

    app = QApplication(["participant_states"])
    for spec in argv:
        size = tuple(int(n) for n in spec.split("x"))
        for state in STATES:
            print(json.dumps(render(size, state)), flush=True)
    app.quit()


if __name__ == "__main__":
    main(sys.argv[1:])
