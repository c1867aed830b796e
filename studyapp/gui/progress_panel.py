"""The console's "Progress" box: the session's state, the step, the condition, the last response, a knob's pickup.

A view of the session controller's events (studyapp.live): the state in
words (``STATE_WORDS``, red for the emergency stop), the task's heading and
"Trial x of y, step n of N" with a progress bar, the current condition (or
"hidden (blinding)"), the last response as its task type words it, and a
physical knob waiting for pickup.
"""

from PySide6.QtWidgets import QGroupBox, QLabel, QProgressBar, QVBoxLayout

from studyapp.engine.safety import force_off_text
from studyapp.experiment.tasks import task_type
from studyapp.live.states import REST, State

STATE_WORDS = {
    State.IDLE: "No session", State.STARTING: "Starting the session's engine…", State.RUNNING: "Running",
    State.PAUSED: "Paused", State.EMERGENCY: force_off_text("operator"),
    State.CLEARING: "Clearing the emergency stop…", State.ENGINE_LOST: "Paused: the engine stopped",
    State.RESTARTING: "Starting a new engine…", State.FINISHED: "Session complete", State.ABORTED: "Session aborted",
}


class ProgressPanel(QGroupBox):
    def __init__(self, parent=None):
        super().__init__("Progress", parent)
        self.state_label = QLabel("No session")
        self.state_label.setStyleSheet("font-weight: bold;")
        self.task_label = QLabel("")
        self.trial_label = QLabel("")
        self.progress_bar = QProgressBar()
        self.progress_bar.setTextVisible(True)
        self.condition_label = QLabel("")
        self.response_label = QLabel("")
        self.pickup_label = QLabel("")  # a physical knob waiting for pickup (engine/pickup.py)
        self.pickup_label.setStyleSheet("color: #06c; font-weight: bold;")
        self.condition_text = ""
        for label in (self.state_label, self.task_label, self.trial_label, self.condition_label,
                      self.response_label, self.pickup_label):
            label.setWordWrap(True)
        self.condition_caption = QLabel("Current condition:")
        p = QVBoxLayout(self)
        p.addWidget(self.state_label)
        p.addWidget(self.task_label)
        p.addWidget(self.trial_label)
        p.addWidget(self.progress_bar)
        p.addWidget(self.condition_caption)
        p.addWidget(self.condition_label)
        p.addWidget(self.response_label)
        p.addWidget(self.pickup_label)
        self._tidy()

    def _tidy(self):
        """Empty lines take no room: the box stays in view below the set-up at 1,366 x 768 (issue 41, item 11)."""
        for label in (self.task_label, self.trial_label, self.condition_label, self.response_label,
                      self.pickup_label):
            label.setVisible(bool(label.text()))
        self.condition_caption.setVisible(bool(self.condition_label.text()))
        self.progress_bar.setVisible(bool(self.trial_label.text()))

    def show_state(self, state, stop_text=STATE_WORDS[State.EMERGENCY]):
        """``stop_text``: what holds the force while the state is EMERGENCY (the controller's ``stop_text``)."""
        emergency = state == State.EMERGENCY
        self.state_label.setText(stop_text if emergency else STATE_WORDS[state])
        self.state_label.setStyleSheet("font-weight: bold;" + (" color: #c00;" if emergency else ""))
        if state in REST:
            self.task_label.setText("")
            if state != State.IDLE:
                self.trial_label.setText(STATE_WORDS[state])
        self._tidy()

    def show_trial(self, trial, step, total, phase, number, of):
        # a practice trial is no repetition of the study's ("adjustment, repetition 2" on practice: issue 41)
        heading = f"{trial.task}, practice" if phase == "practice" else task_type(trial.task).heading(trial)
        self.task_label.setText("Task: " + heading)
        counted = "" if phase == "page" else f"{'Practice' if phase == 'practice' else 'Trial'} {number} of {of}, "
        self.trial_label.setText(f"{counted}step {step + 1} of {total}")
        self.progress_bar.setRange(0, total)
        self.progress_bar.setValue(step)
        self._tidy()

    def show_selection(self, source, fmax):
        text = source or "none selected yet"
        if fmax is not None:
            text += f" at F_max = {fmax:.3g} N"
        self.condition_text = text

    def show_condition(self, hidden):
        self.condition_label.setText("hidden (blinding)" if hidden else self.condition_text)
        self._tidy()

    def show_response(self, response, step):
        self.response_label.setText(task_type(response["task"]).response_text(response))
        self.progress_bar.setValue(step + 1)
        self._tidy()

    def show_pickup(self, control, pending, text):
        self.pickup_label.setText(f"{control}: {text}" if pending else "")
        self._tidy()
