"""The console's session buttons: Start, Pause/Resume, Abort and the EMERGENCY STOP, always in view.

Pause/Resume is one button: Pause while a trial runs; Resume gives a paused
trial back, clears the emergency stop, or starts a new engine after a lost
one (the controller's ``resume``, ``clear_emergency``, ``restart_engine``).
Start and Abort call back into the console (which asks before an abort and
starts the simulated participant).
"""

from PySide6.QtWidgets import QHBoxLayout, QPushButton, QVBoxLayout, QWidget

from studyapp.live.states import REST, State

STOP_STYLE = ("QPushButton { background: #c00; color: white; font-weight: bold; font-size: 14pt; "
              "padding: 10px; border-radius: 4px; } QPushButton:pressed { background: #800; }")


class SessionButtons(QWidget):
    def __init__(self, controller, start, abort, parent=None):
        super().__init__(parent)
        self.controller = controller
        self.start_button = QPushButton("Start session")
        # not connected directly: ``clicked`` passes ``checked`` (False), which became the seed 0
        self.start_button.clicked.connect(lambda: start())
        self.pause_button = QPushButton("Pause")
        self.pause_button.clicked.connect(self._pause_or_resume)
        self.abort_button = QPushButton("Abort")
        self.abort_button.clicked.connect(lambda: abort(confirm=True))
        self.stop_button = QPushButton("EMERGENCY STOP")
        self.stop_button.setStyleSheet(STOP_STYLE)
        self.stop_button.setToolTip("zero the force now (Esc)")
        self.stop_button.clicked.connect(lambda: controller.emergency_stop("operator"))
        row = QHBoxLayout()
        row.addWidget(self.start_button)
        row.addWidget(self.pause_button)
        row.addWidget(self.abort_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addLayout(row)
        layout.addWidget(self.stop_button)

    def show_state(self, state, in_session):
        self.start_button.setEnabled(state in REST)
        self.abort_button.setEnabled(in_session)
        self.pause_button.setEnabled(state in (State.RUNNING, State.PAUSED, State.EMERGENCY, State.ENGINE_LOST))
        # "Resume" only where there is something to resume: idle, starting or finished it reads "Pause" (greyed)
        self.pause_button.setText("Resume" if state in (State.PAUSED, State.EMERGENCY, State.ENGINE_LOST)
                                  else "Pause")

    def _pause_or_resume(self):
        c = self.controller
        act = {State.EMERGENCY: c.clear_emergency, State.PAUSED: c.resume, State.ENGINE_LOST: c.restart_engine}
        act.get(c.state, c.pause)()
