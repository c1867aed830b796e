"""On-screen knobs and pads, mirroring the MIDI controller's (an LPD8: 8 knobs, 8 pads).

Knob i (from 0) is a dial over the MIDI range 0..127; turning it with the
mouse (drag or wheel) emits ``knob_turned(i, value)`` for every position it
passes, as a hardware knob sends a control change per step. A pad is a
button; clicking it emits ``pad_pressed(i)``. ``show_knob(i, value)`` moves a
dial to what the session is using (a MIDI knob turned, a trial's starting
position) without emitting anything, so the screen mirrors the hardware.

Labels are "K1".."K8" and "P1".."P8", as printed on the LPD8; ``set_captions``
can add a line under each knob (e.g. its condition, on the experimenter's
console only, and hidden for blinding).
"""

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QDial, QGridLayout, QLabel, QPushButton, QSizePolicy, QVBoxLayout, QWidget

KNOB_MAX = 127
PAD_MIN_WIDTH = 36  # px


class KnobPanel(QWidget):
    knob_turned = Signal(int, int)
    pad_pressed = Signal(int)

    def __init__(self, knobs=8, pads=8, parent=None):
        super().__init__(parent)
        self.dials = []
        self.values = []
        self.captions = []
        self.pads = []
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.setHorizontalSpacing(4)
        grid.setVerticalSpacing(2)
        columns = max(knobs, pads)
        for i in range(knobs):
            dial = QDial()
            dial.setRange(0, KNOB_MAX)
            dial.setNotchesVisible(True)
            dial.setWrapping(False)
            dial.setFixedSize(48, 48)
            dial.setToolTip(f"knob {i + 1} (MIDI 0..{KNOB_MAX})")
            dial.valueChanged.connect(lambda value, i=i: self._turned(i, value))
            value = QLabel(f"K{i + 1}: 0")
            value.setAlignment(Qt.AlignmentFlag.AlignCenter)
            caption = QLabel("")
            caption.setAlignment(Qt.AlignmentFlag.AlignCenter)
            caption.setStyleSheet("color: #555; font-size: 8pt;")
            box = QVBoxLayout()
            box.setSpacing(0)
            box.addWidget(dial, 0, Qt.AlignmentFlag.AlignHCenter)
            box.addWidget(value)
            box.addWidget(caption)
            grid.addLayout(box, 0, i)
            self.dials.append(dial)
            self.values.append(value)
            self.captions.append(caption)
        for i in range(pads):
            pad = QPushButton(f"P{i + 1}")
            pad.setMinimumSize(PAD_MIN_WIDTH, 30)  # not the style's ~80 px: eight of them fit a laptop's console
            pad.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
            pad.setToolTip(f"pad {i + 1}")
            pad.clicked.connect(lambda checked=False, i=i: self.pad_pressed.emit(i))
            grid.addWidget(pad, 1, i)
            self.pads.append(pad)
        for column in range(columns):
            grid.setColumnStretch(column, 1)

    def _turned(self, index, value):
        self.values[index].setText(f"K{index + 1}: {value}")
        self.knob_turned.emit(index, value)

    def show_knob(self, index, value):
        """Move dial ``index`` to ``value`` without emitting ``knob_turned``."""
        if not 0 <= index < len(self.dials):
            return
        dial = self.dials[index]
        dial.blockSignals(True)
        dial.setValue(int(value))
        dial.blockSignals(False)
        self.values[index].setText(f"K{index + 1}: {int(value)}")

    def turn(self, index, value):
        """Set knob ``index`` to ``value`` as a hand would: ``knob_turned`` even if it is already there."""
        dial = self.dials[index]
        if dial.value() == int(value):
            self._turned(index, int(value))
        else:
            dial.setValue(int(value))

    def press(self, index):
        """Press pad ``index`` as the mouse would."""
        self.pads[index].click()

    def set_captions(self, captions):
        for i, label in enumerate(self.captions):
            label.setText(captions[i] if i < len(captions) else "")
