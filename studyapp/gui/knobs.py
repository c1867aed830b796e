"""On-screen knobs and pads, mirroring the MIDI controller's (an LPD8: 8 knobs, 8 pads).

Knob i (from 0) is a dial over the MIDI range 0..127; turning it with the
mouse (drag or wheel) emits ``knob_turned(i, value)`` for every position it
passes, as a hardware knob sends a control change per step. A pad is a
button; clicking it emits ``pad_pressed(i)``. ``show_knob(i, value)`` moves a
dial to what the session is using (a MIDI knob turned, a trial's starting
position) without emitting anything, so the screen mirrors the hardware.

The experimenter's panel labels them "K1".."K8" (with the knob's value) and
"P1".."P8", as printed on the LPD8; ``set_captions`` can add a line under each
knob (e.g. its condition, hidden for blinding).

The participant's panel (``participant=True``) gives nothing away: its dials
are large and bare (no value, no notches, no caption, no tooltip: a number
invites anchoring a rating on it), ``set_captions`` shows nothing, and
``show_only`` leaves visible just the knobs the trial uses and its pads,
named in words (e.g. "Done"). Its controls never take the keyboard focus, so
the space bar reaches the window (the bow) instead of pressing a button. A
dial the participant has not set yet in a trial (``mark_unset``) is drawn
as an empty dashed ring with no pointer: at its resting position (the bottom)
an unrated dial would read as "noisiest". Its first turn draws it as a dial.
"""

from PySide6.QtCore import QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPen
from PySide6.QtWidgets import (
    QDial,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from studyapp.model.controls import KNOB_MAX

PAD_MIN_WIDTH = 36  # px
PARTICIPANT_DIAL = 110  # px: a large target for the mouse, eight of them fit in 1,366 px


class ParticipantDial(QDial):
    """The participant's dial; ``unset`` (not turned yet in this trial) draws an empty dashed ring."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.unset = False

    def set_unset(self, on):
        if self.unset != bool(on):
            self.unset = bool(on)
            self.update()

    def paintEvent(self, event):
        if not self.unset:
            super().paintEvent(event)
            return
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        side = min(self.width(), self.height()) - 8
        ring = QRectF((self.width() - side) / 2, (self.height() - side) / 2, side, side)
        p.setBrush(QColor("#f4f4f4"))
        p.setPen(QPen(QColor("#888"), 2, Qt.PenStyle.DashLine))
        p.drawEllipse(ring)
        p.end()


class KnobPanel(QWidget):
    knob_turned = Signal(int, int)
    pad_pressed = Signal(int)

    def __init__(self, knobs=8, pads=8, parent=None, participant=False):
        super().__init__(parent)
        self.participant = participant
        self.dials = []
        self.values = []
        self.captions = []
        self.pads = []
        for i in range(knobs):
            dial = ParticipantDial() if participant else QDial()
            dial.setRange(0, KNOB_MAX)
            dial.setWrapping(False)
            dial.valueChanged.connect(lambda value, i=i: self._turned(i, value))
            self.dials.append(dial)
        for i in range(pads):
            pad = QPushButton("" if participant else f"P{i + 1}")
            pad.clicked.connect(lambda checked=False, i=i: self.pad_pressed.emit(i))
            self.pads.append(pad)
        if participant:
            self._participant_layout()
        else:
            self._console_layout()

    def _console_layout(self):
        grid = QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.setHorizontalSpacing(4)
        grid.setVerticalSpacing(2)
        for i, dial in enumerate(self.dials):
            dial.setNotchesVisible(True)
            dial.setFixedSize(48, 48)
            dial.setToolTip(f"knob {i + 1} (MIDI 0..{KNOB_MAX})")
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
            self.values.append(value)
            self.captions.append(caption)
        for i, pad in enumerate(self.pads):
            pad.setMinimumSize(PAD_MIN_WIDTH, 30)  # not the style's ~80 px: eight of them fit a laptop's console
            pad.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
            pad.setToolTip(f"pad {i + 1}")
            grid.addWidget(pad, 1, i)
        for column in range(max(len(self.dials), len(self.pads))):
            grid.setColumnStretch(column, 1)

    def _participant_layout(self):
        # box layouts, not a grid: a hidden dial or pad then takes no room at all
        for dial in self.dials:
            dial.setNotchesVisible(False)
            dial.setFixedSize(PARTICIPANT_DIAL, PARTICIPANT_DIAL)
            dial.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self._dial_row = QHBoxLayout()
        self._dial_row.setSpacing(12)
        self._space_dials(self.dials)
        pads = QHBoxLayout()
        pads.addStretch(1)
        for pad in self.pads:
            pad.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            pad.setMinimumHeight(56)
            pads.addWidget(pad)
        column = QVBoxLayout(self)
        column.setContentsMargins(0, 0, 0, 0)
        column.setSpacing(16)
        column.addLayout(self._dial_row)
        column.addLayout(pads)

    def _space_dials(self, shown):
        """The participant's row: the ``shown`` dials spread evenly across the width."""
        row = self._dial_row
        while row.count():
            row.takeAt(0)
        row.addStretch(1)
        for dial in shown:
            row.addWidget(dial)
            row.addStretch(1)

    def _turned(self, index, value):
        self._show_value(index, value)
        self._set(index)
        self.knob_turned.emit(index, value)

    def mark_unset(self, indices):
        """The participant's dials ``indices`` are not set yet (drawn as empty rings); the others are."""
        if self.participant:
            for i, dial in enumerate(self.dials):
                dial.set_unset(i in indices)

    def _set(self, index):
        if self.participant and 0 <= index < len(self.dials):
            self.dials[index].set_unset(False)

    def _show_value(self, index, value):
        if self.values:
            self.values[index].setText(f"K{index + 1}: {int(value)}")

    def show_knob(self, index, value):
        """Move dial ``index`` to ``value`` without emitting ``knob_turned``."""
        if not 0 <= index < len(self.dials):
            return
        dial = self.dials[index]
        dial.blockSignals(True)
        dial.setValue(int(value))
        dial.blockSignals(False)
        self._show_value(index, value)
        self._set(index)

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

    def show_only(self, knobs, pads, pad_text=""):
        """Show just the dials in ``knobs`` and the pads in ``pads`` (indices from 0); the pads read ``pad_text``."""
        for i, dial in enumerate(self.dials):
            dial.setVisible(i in knobs)
        if self.participant:
            self._space_dials([dial for i, dial in enumerate(self.dials) if i in knobs])
        for i, pad in enumerate(self.pads):
            pad.setVisible(i in pads)
            if pad_text:
                pad.setText(pad_text)

    def visible_knobs(self):
        """The indices of the dials shown (what a participant can turn)."""
        return [i for i, dial in enumerate(self.dials) if not dial.isHidden()]
