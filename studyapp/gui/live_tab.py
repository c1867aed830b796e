"""The console's "Live" tab: the scope, the on-screen knobs and pads, and the bowing pad with the hand's gesture.

Every control calls the session controller (studyapp.live) as a MIDI knob
or pad would reach it; the controller's events move them back (a knob the
worker applied, the bow lifted at a page, the gesture a trial starts with).
"""

from PySide6.QtWidgets import QComboBox, QGroupBox, QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from studyapp.gui.bowing_pad import BowingPad
from studyapp.gui.knobs import KnobPanel
from studyapp.gui.scope import Scope
from studyapp.model.limits import CONSOLE_GESTURES


class LiveTab(QWidget):
    def __init__(self, controller, parent=None):
        super().__init__(parent)
        self.scope = Scope()
        self.scope.saved.connect(lambda path: controller.message(f"scope saved to {path}"))
        self.knobs = KnobPanel()
        self.knobs.knob_turned.connect(controller.knob)
        self.knobs.pad_pressed.connect(controller.pad)
        self.bowing_pad = BowingPad()
        self.bowing_pad.bow_pressed.connect(controller.bow_press)
        self.bowing_pad.bow_moved.connect(controller.bow_move)
        self.bowing_pad.bow_released.connect(controller.bow_release)
        self.gesture = QComboBox()
        self.gesture.addItems(CONSOLE_GESTURES)
        self.gesture.setToolTip("the virtual hand: scripted strokes, holding the handle still, or the mouse (pad)")
        self.gesture.activated.connect(lambda index: controller.set_gesture(self.gesture.itemText(index)))
        self.bow_button = QPushButton("Bow")
        self.bow_button.setCheckable(True)
        self.bow_button.setStyleSheet("QPushButton:checked { background: #bcd7f0; font-weight: bold; }")
        self.bow_button.setToolTip("put the bow on the string (the hand moves as the gesture says)")
        self.bow_button.toggled.connect(controller.set_bowing)
        knob_box = QGroupBox("Knobs and pads (mirror the MIDI controller)")
        QVBoxLayout(knob_box).addWidget(self.knobs)
        bow_box = QGroupBox("Bowing")
        bv = QVBoxLayout(bow_box)
        bv.addWidget(self.bowing_pad)
        row = QHBoxLayout()
        row.addWidget(QLabel("Hand"))
        row.addWidget(self.gesture, 1)
        row.addWidget(self.bow_button, 1)
        bv.addLayout(row)
        controls = QHBoxLayout()
        controls.addWidget(knob_box, 3)
        controls.addWidget(bow_box, 1)
        layout = QVBoxLayout(self)
        layout.addWidget(self.scope, 1)
        layout.addLayout(controls)

    def set_accepting(self, accepting):
        """The participant's controls act (a trial plays, or live use outside a session), or not."""
        for widget in (self.knobs, self.bowing_pad, self.gesture, self.bow_button):
            widget.setEnabled(accepting)

    def show_bowing(self, on):
        self.bow_button.blockSignals(True)
        self.bow_button.setChecked(bool(on))
        self.bow_button.blockSignals(False)

    def show_gesture(self, name):
        self.gesture.setCurrentIndex(self.gesture.findText(name))

    def show_telemetry(self, block):
        self.scope.add(block)
        if len(block["position"]):
            self.bowing_pad.show_handle(block["position"][-1])
