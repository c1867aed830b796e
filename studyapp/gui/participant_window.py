"""The participant's window: the task's instructions, progress, and nothing that reveals the condition.

Between trials it shows the session's pages (welcome, instructions, breaks,
...: ``page_view.PageView``) in place of the instructions and knobs; its
Continue button is ``page_view.continued``. Progress counts the current
task's practice or real trials ("Practice 1 of 2", "Trial 2 of 12"); a
refused confirm shows its reason (which names knobs, never conditions).

Shown on a second screen (or not at all). It never names an estimator, a
condition, F_max or a knob's meaning: only the study's title, the current
task's instructions from the protocol, "trial x of y", and whether the session
is paused. It carries its own on-screen knobs and pads (without captions) for
a participant who has no MIDI controller; they act exactly like the
console's.
"""

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from studyapp.gui.knobs import KnobPanel
from studyapp.gui.page_view import PageView

MESSAGES = {
    "idle": "Please wait: the session has not started yet.",
    "starting": "Please wait: the session is starting.",
    "paused": "Paused. Please wait for the experimenter.",
    "finished": "Thank you! The session is complete.",
    "aborted": "The session has been stopped. Thank you.",
}


class ParticipantWindow(QWidget):
    def __init__(self, knobs=8, pads=8, parent=None):
        super().__init__(parent, Qt.WindowType.Window)
        self.setWindowTitle("Study")
        self.title = QLabel("")
        self.title.setStyleSheet("font-size: 20pt; font-weight: bold;")
        self.progress = QLabel("")
        self.progress.setStyleSheet("font-size: 14pt; color: #444;")
        self.instructions = QLabel("")
        self.instructions.setWordWrap(True)
        self.instructions.setStyleSheet("font-size: 16pt;")
        self.instructions.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        self.notice = QLabel(MESSAGES["idle"])
        self.notice.setStyleSheet("font-size: 16pt; color: #a60;")
        self.pickup = QLabel("")
        self.pickup.setStyleSheet("font-size: 16pt; color: #06c;")
        self.knobs = KnobPanel(knobs, pads)
        self.page_view = PageView()
        self.page_view.hide()
        layout = QVBoxLayout(self)
        layout.addWidget(self.title)
        layout.addWidget(self.progress)
        layout.addWidget(self.instructions, 1)
        layout.addWidget(self.page_view, 1)
        layout.addWidget(self.notice)
        layout.addWidget(self.pickup)
        layout.addWidget(self.knobs)
        self.resize(900, 560)

    def show_title(self, title):
        self.title.setText(title)

    def show_trial(self, step, total, instructions, phase="trial", number=None, of=None):
        self._show_page_view(phase == "page")
        if phase != "page":
            word = "Practice" if phase == "practice" else "Trial"
            self.progress.setText(f"{word} {number} of {of}" if number else f"Trial {step + 1} of {total}")
        self.instructions.setText(instructions)
        self.notice.setText("")

    def show_page(self, kind, title, text, by):
        """A page in place of the instructions and knobs (``text`` in Markdown)."""
        self._show_page_view(True)
        self.progress.setText("")
        self.page_view.show_page(kind, title, text, by)

    def _show_page_view(self, on):
        self.page_view.setVisible(on)
        self.instructions.setVisible(not on)
        self.knobs.setVisible(not on)

    def show_refusal(self, reason):
        """Why a confirm was not taken (blind-safe: the tasks name knobs, not conditions)."""
        self.notice.setText(f"Not yet: {reason}")

    def show_pickup(self, text):
        """A physical knob waiting for pickup: say which way to turn it ("" once it acts)."""
        self.pickup.setText(text)

    def show_state(self, state, emergency=False):
        if emergency:
            self.notice.setText(MESSAGES["paused"])
        else:
            self.notice.setText(MESSAGES.get(state, ""))
        if state in ("finished", "aborted", "idle"):
            self.instructions.setText("")
            self._show_page_view(False)
        self.knobs.setEnabled(state == "running" and not emergency)
