"""The participant's window: the task's instructions, progress, the controls the trial uses, and nothing that reveals the condition.

Shown on a second screen, full-screen (``show_full_screen``), or not at all.
It never names an estimator, a condition, F_max or a knob's meaning, and
never shows a knob's value or the study's aim: only the protocol's
``participant_title`` (neutral by default; never its ``title``), the current task's
instructions from the protocol, "trial x of y", whether the session is
paused, and whether the bow is on the string.

**Controls.** Its own dials and pads (``KnobPanel`` in participant mode) act
exactly like the console's. During a trial it shows only the knobs the
trial's task type maps (``knob_actions``: knob j of a rating trial plays the
trial's ``conditions[j]``; an adjustment trial has its one knob) and the
trial's confirm pad, as a "Done" button; outside a trial, none. The bow is
the "Bow" toggle or the space bar, through the controller's ``set_bowing``;
"Bowing" / "Bow lifted" follows the controller's ``bowing`` event, so it is
right whoever moved the bow (console, participant, protocol).

**The bowing surface** (``bowing_surface.BowingSurface``): in a trial of a
task whose bow is the participant's (``bow = "participant"``, the default),
a full-width surface where the pointer (mouse, trackpad, pen) is the hand on
the handle: pressing bows, moving moves the hand's target, releasing lifts
the bow (the console connects it to the controller's ``bow_press``,
``bow_move`` and ``bow_release``, as its own bowing pad). The Bow toggle and
the space bar still put the bow on the string with the protocol's gesture.
A space press within ``BOUNCE_S`` of the last toggle is ignored: no person
means to lift the bow 25 ms after putting it down, and the second toggle
logged a bow on and off at once when a trial had just appeared.

**Refusals.** A refused confirm (the controller's ``refused`` event) is shown by ``show_refusal`` in the participant's words: a condition's
name, or "knob N", becomes the dial that plays it ("the second dial"), F_max "the level".

**Legibility.** Body text is ``BODY_PT`` = 22 pt, headings 28 pt. ISO
9241-303 asks for characters of at least 16 arcmin, preferably 20 to 22
arcmin; from 60 cm, 22 arcmin is a 3.8 mm capital, i.e. about 16 pt on a
96-dpi screen. 22 pt (about 31 arcmin) keeps that margin on a laptop's
denser pixels and for a participant leaning back. The instructions take
whatever height is left.

**Pages.** Between trials it shows the session's pages (welcome,
instructions, breaks, ...: ``page_view.PageView``, Markdown) in place of the
instructions and controls; its Continue button is ``page_view.continued``.
Progress counts the current task's practice or real trials ("Practice 1 of
2", "Trial 2 of 12").
"""

import re
import time

from PySide6.QtCore import QEvent, Qt
from PySide6.QtWidgets import QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from studyapp.estimators import names as estimator_names
from studyapp.experiment.tasks import task_type
from studyapp.gui.bowing_surface import BowingSurface
from studyapp.gui.knobs import KnobPanel
from studyapp.gui.page_view import PageView
from studyapp.model.controls import Select

BODY_PT = 22
HEADING_PT = 28
MESSAGES = {
    "idle": "Please wait: the session has not started yet.",
    "starting": "Please wait: the session is starting.",
    "paused": "Paused. Please wait for the experimenter.",
    "finished": "Thank you! The session is complete.",
    "aborted": "The session has been stopped. Thank you.",
}
ACTIVE = ("running", "paused", "emergency", "clearing", "engine_lost", "restarting")  # a trial is on screen
REFUSED = "confirm refused: "
ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth")
PLAIN_WORDS = (("F_max is 0", "nothing is playing yet"), ("F_max", "the level"))
DONE = "Done"
BOUNCE_S = 0.15  # s: a second space toggle sooner than this is a bounce, not a decision
BOW_ON, BOW_OFF = "Bowing", "Bow lifted"


def reflow(text):
    """The protocol's instructions as paragraphs: TOML's line breaks inside a paragraph become spaces."""
    paragraphs = re.split(r"\n\s*\n", text.strip())
    return "\n\n".join(" ".join(p.split()) for p in paragraphs if p.strip())


def _knob(control):
    return int(control[4:]) - 1 if control.startswith("knob") and control[4:].isdigit() else None


def trial_controls(trial, state):
    """What a trial's participant uses: ``(knobs, pads, sounds)``.

    ``knobs``: the knobs its task type maps (``knob_actions``); ``pads``: its
    confirm pad, if it has one; ``sounds``: each name in a knob's action (the
    condition it selects) -> that knob, so a refusal can name the dial instead.
    """
    knobs, sounds = [], {}
    for control, action in task_type(trial.task).knob_actions(trial, state).items():
        knob = _knob(control)
        if knob is None:
            continue
        knobs.append(knob)
        if isinstance(action, Select):
            sounds.setdefault(action.condition, knob)
    pad = getattr(state, "confirm_pad", None)
    return sorted(knobs), ([] if pad is None else [pad]), sounds


def _label(size, style=""):
    label = QLabel("")
    label.setWordWrap(True)
    label.setStyleSheet(f"font-size: {size}pt; {style}")
    return label


class ParticipantWindow(QWidget):
    def __init__(self, controller=None, knobs=8, pads=8, parent=None, clock=time.monotonic):
        super().__init__(parent, Qt.WindowType.Window)
        self.controller = controller
        self.clock = clock
        self.bowing = False
        self.running = False
        self._sounds = {}
        self._toggled = -BOUNCE_S  # self.clock() at the last space toggle
        self.setWindowTitle("Study")
        self.title = _label(HEADING_PT, "font-weight: bold;")
        self.progress = _label(BODY_PT, "color: #444;")
        self.instructions = _label(BODY_PT)
        self.instructions.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        self.notice = _label(BODY_PT, "color: #a60;")
        self.notice.setText(MESSAGES["idle"])
        self.refusal = _label(BODY_PT, "color: #b00;")
        self.pickup = _label(BODY_PT, "color: #06c;")
        self.bow_button = QPushButton("Bow")
        self.bow_button.setCheckable(True)
        self.bow_button.setFocusPolicy(Qt.FocusPolicy.NoFocus)  # the space bar is the window's
        self.bow_button.setMinimumHeight(56)
        self.bow_button.setStyleSheet(f"QPushButton {{ font-size: {BODY_PT}pt; padding: 4px 32px; }}"
                                      "QPushButton:checked { background: #bcd7f0; font-weight: bold; }")
        self.bow_button.clicked.connect(self.toggle_bowing)
        self.bow_state = _label(BODY_PT)
        self.bow_hint = _label(BODY_PT, "color: #666;")
        self.bow_hint.setText("(or the space bar)")
        self.surface = BowingSurface(BODY_PT)
        self.knobs = KnobPanel(knobs, pads, participant=True)
        self.knobs.setStyleSheet(f"QPushButton {{ font-size: {BODY_PT}pt; padding: 4px 48px; }}")
        bow_row = QHBoxLayout()
        bow_row.setSpacing(16)
        bow_row.addWidget(self.bow_button)
        bow_row.addWidget(self.bow_state)
        bow_row.addWidget(self.bow_hint, 1)
        self.bow_row = QWidget()
        self.bow_row.setLayout(bow_row)
        bow_row.setContentsMargins(0, 0, 0, 0)
        self.page_view = PageView()
        self.page_view.hide()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(40, 24, 40, 24)  # a 1,366 x 768 screen holds a rating trial's every control
        layout.setSpacing(10)
        layout.addWidget(self.title)
        layout.addWidget(self.progress)
        layout.addWidget(self.instructions, 1)
        layout.addWidget(self.surface, 1)
        layout.addWidget(self.page_view, 1)
        layout.addWidget(self.notice)
        layout.addWidget(self.refusal)
        layout.addWidget(self.pickup)
        layout.addWidget(self.bow_row)
        layout.addWidget(self.knobs)
        self.show_bowing(False)
        self.show_controls([], [])
        self.show_title("")
        self._hide_empty()
        if controller is not None:
            e = controller.events
            e.trial.connect(self._on_trial)
            e.bowing.connect(self.show_bowing)
            e.refused.connect(lambda reason: self.show_refusal(reason))
        for widget in self.findChildren(QWidget):  # no child takes a key: Space is the bow, Esc the stop
            widget.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.resize(1000, 700)

    # what the console (or the controller's events) tell it --------------------------
    def show_title(self, title):
        """The title the participant sees (the protocol's ``participant_title``)."""
        self.title.setText(title)
        self.title.setVisible(bool(title))

    def show_trial(self, step, total, instructions, phase="trial", number=None, of=None):
        self._show_page_view(phase == "page")
        if phase != "page":
            word = "Practice" if phase == "practice" else "Trial"
            self.progress.setText(f"{word} {number} of {of}" if number else f"Trial {step + 1} of {total}")
        self.instructions.setText(reflow(instructions))
        self.show_refusal("")

    def show_page(self, kind, title, text, by):
        """A page in place of the instructions and controls (``text`` in Markdown)."""
        self._show_page_view(True)
        self.progress.setText("")
        self.page_view.show_page(kind, title, text, by)

    def _show_page_view(self, on):
        """A page replaces the instructions and the trial's controls (``show_controls`` gives them back)."""
        self.page_view.setVisible(on)
        self.instructions.setVisible(not on)
        if on:
            self.knobs.setVisible(False)
            self.bow_row.setVisible(False)
            self.surface.setVisible(False)

    def show_pickup(self, text):
        """A physical knob waiting for pickup: say which way to turn it ("" once it acts)."""
        self.pickup.setText(text)
        self._hide_empty()

    def show_state(self, state, emergency=False):
        self.notice.setText(MESSAGES["paused"] if emergency else MESSAGES.get(state, ""))
        if state not in ACTIVE:
            self.progress.setText("")
            self.instructions.setText("")
            self._show_page_view(False)
            self.show_controls([], [])
            self.show_refusal("")
        self.running = state == "running" and not emergency
        self.knobs.setEnabled(self.running)
        self.bow_button.setEnabled(self.running)
        self.surface.setEnabled(self.running)
        self._hide_empty()

    def show_controls(self, knobs, pads, sounds=None, surface=False):
        """Show the dials ``knobs`` and the pads ``pads`` (as "Done"), the bow row if any is shown, and
        the bowing surface (``surface``: the participant bows)."""
        self.knobs.show_only(knobs, pads, DONE)
        self.knobs.setVisible(bool(knobs or pads))
        self.bow_row.setVisible(bool(knobs or pads))
        self.surface.bowing = False  # a press left over from the last trial bows nothing
        self.surface.setVisible(bool(surface))
        self._sounds = dict(sounds or {})

    def show_bowing(self, on):
        """The bow is on the string (True) or lifted: the toggle and the words follow."""
        self.bowing = bool(on)
        if not self.bowing and self.surface.bowing:  # lifted elsewhere: press again to bow
            self.surface.bowing = False
            self.surface.update()
        self.bow_button.setChecked(self.bowing)
        self.bow_state.setText(BOW_ON if self.bowing else BOW_OFF)
        self.bow_state.setStyleSheet(f"font-size: {BODY_PT}pt; font-weight: bold; "
                                     f"color: {'#06c' if self.bowing else '#555'};")

    def show_refusal(self, text):
        """Why a confirm was refused, in the participant's words ("" clears it)."""
        self.refusal.setText(self.plain(text))
        self._hide_empty()

    def plain(self, reason):
        """``reason`` without a condition's name (the dial that plays it instead) or the model's terms."""
        reason = reason.strip()
        if reason.startswith(REFUSED):
            reason = reason[len(REFUSED):]
        if not reason:
            return ""
        shown = self.knobs.visible_knobs()

        def named(knob):
            if knob in shown and shown.index(knob) < len(ORDINALS):
                return f"the {ORDINALS[shown.index(knob)]} dial"
            return "one of the dials"

        names = sorted(estimator_names(), key=len, reverse=True)
        reason = re.sub(r"\b(" + "|".join(map(re.escape, names)) + r")\b",
                        lambda match: named(self._sounds.get(match.group(0))), reason)
        reason = re.sub(r"\bknob (\d+)\b", lambda match: named(int(match.group(1)) - 1), reason)
        for term, words in PLAIN_WORDS:
            reason = reason.replace(term, words)
        return reason[0].upper() + reason[1:] + ("" if reason.endswith(".") else ".")

    # the bow ------------------------------------------------------------------
    def toggle_bowing(self):
        """The participant lifts the bow, or puts it on the string (only while a trial runs)."""
        if self.running and self.controller is not None:
            self.controller.set_bowing(not self.bowing)
        self.show_bowing(self.bowing)  # a refused toggle leaves the button as the bow is

    def event(self, event):
        # Esc here is the participant's: taken before the console's application-wide shortcut (the operator's)
        if event.type() == QEvent.Type.ShortcutOverride and event.key() == Qt.Key.Key_Escape:
            event.accept()
            return True
        return super().event(event)

    def keyPressEvent(self, event):
        if event.key() == Qt.Key.Key_Escape:
            if self.controller is not None:
                self.controller.emergency_stop("participant")
            return
        if event.key() == Qt.Key.Key_Space:
            now = self.clock()
            if not event.isAutoRepeat() and now - self._toggled >= BOUNCE_S:
                self._toggled = now
                self.toggle_bowing()
            return
        super().keyPressEvent(event)

    # the controller's events ------------------------------------------------------
    def _on_trial(self, trial, step, total, instructions, **_):
        runner = self.controller.runner
        knobs, pads, sounds = trial_controls(trial, runner.task)
        protocol = self.controller.protocol
        spec = protocol.specs.get(trial.task) if protocol is not None else None
        self.show_controls(knobs, pads, sounds, surface=getattr(spec, "bow", None) == "participant")
        self.knobs.mark_unset([k for k in knobs if k not in runner.task.knob_positions()])

    def _hide_empty(self):
        for label in (self.notice, self.refusal, self.pickup):
            label.setVisible(bool(label.text()))

    # the screen ---------------------------------------------------------------------
    def show_full_screen(self, screen):
        """Open (when shown) full-screen on ``screen`` (a ``QScreen``)."""
        self.setScreen(screen)
        self.setGeometry(screen.geometry())
        self.setWindowState(self.windowState() | Qt.WindowState.WindowFullScreen)
