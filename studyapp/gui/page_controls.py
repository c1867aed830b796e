"""The console's view of the page the participant sees: its title, and the experimenter's confirm.

During a page step it says which page is showing and who goes on from it.
For the headphone level check (a ``calibration`` page) it names the tone and
level playing (its tooltip: how the level was computed, the page's ``note``) and offers "Confirm level", the experimenter's acknowledgement
(``SessionController.acknowledge_page("experimenter")``); the participant
cannot end that page. Hidden between pages.
"""

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QHBoxLayout, QLabel, QPushButton, QWidget


class PageControls(QWidget):
    confirmed = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.label = QLabel("")
        self.label.setWordWrap(True)
        self.confirm_button = QPushButton("Confirm level")
        self.confirm_button.setToolTip("the participant hears the reference tone at a comfortable level: go on")
        self.confirm_button.clicked.connect(self.confirmed)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.label, 1)
        layout.addWidget(self.confirm_button)
        self.show_none()

    def show_page(self, kind, title, by, tone_hz=None, level_dbfs=None, note=""):
        calibration = kind == "calibration"
        if calibration:
            text = f"Page: {title} — reference tone {tone_hz:g} Hz at {level_dbfs:g} dBFS"
        else:
            text = f"Page: {title} ({kind}) — the {by} continues"
        self.label.setText(text)
        self.label.setToolTip(note)  # the level check's computed level: the experimenter's, kept off the page
        self.confirm_button.setVisible(calibration)
        self.setVisible(True)

    def show_none(self):
        self.label.setText("")
        self.confirm_button.setVisible(False)
        self.setVisible(False)
