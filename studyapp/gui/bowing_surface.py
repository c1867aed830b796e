"""The participant's bowing surface: the pointer is the hand on the handle, across the window's full width.

It works as the console's bowing pad (``bowing_pad.BowingPad``, which it
extends): pressing puts the bow on the string and the virtual hand's target
at the pointer (``bow_pressed(x)``), moving moves the target
(``bow_moved(x)``), releasing lifts the bow (``bow_released``); the width
maps onto the handle's travel (+-``REACH``), so the whole surface is the
stroke. Mouse, trackpad and pen tablet alike: a pen's touch is the press.

It shows no number and no handle: only a string across it and where the
participant's hand is (a grip drawn at the pointer while bowing). The real
handle's position is left out on purpose: the paper's participants felt and
heard the string, and a drawn handle shaking with a noisy estimator would be
a visual cue to the condition they did not have.

**Pen pressure.** Qt reports a pen's pressure (``QTabletEvent.pressure``,
0..1); it is kept in ``pressure`` and does *not* set the bow's force. The
force on the handle is the model's friction scaled by F_max, which the
adjustment task asks the participant to find with the knob and the rating
task holds constant (paper Sec. 8.2-8.3): letting the pen scale it would
change the quantity the study measures, and STK's bow-pressure control has no
counterpart in the paper's model. The pen acts as a mouse (Qt turns its
events into mouse events once this widget leaves them unaccepted).
"""

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QFont, QPainter, QPen
from PySide6.QtWidgets import QSizePolicy

from studyapp.gui.bowing_pad import REACH, BowingPad

MIN_HEIGHT = 140  # px: a large target, and room for the words
HINT = "Press here and move left and right to bow"
HINT_BOWING = "Bowing: move left and right, release to lift the bow"


class BowingSurface(BowingPad):
    def __init__(self, font_pt=22, parent=None):
        super().__init__(parent)
        self.font_pt = font_pt
        self.pressure = None  # the pen's latest pressure (0..1), or None (no pen)
        self.setMinimumSize(300, MIN_HEIGHT)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setToolTip("")
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)  # the space bar stays the window's (the bow)

    def tabletEvent(self, event):
        self.pressure = float(event.pressure())
        event.ignore()  # Qt then sends the matching mouse event: the pen acts as a mouse

    def show_handle(self, x_m):
        """The handle is not shown to the participant (see the module docstring)."""

    def paintEvent(self, event):
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        rect = QRectF(self.rect()).adjusted(1, 1, -1, -1)
        p.fillRect(rect, QColor("#efe0c4") if self.bowing else QColor("#f6f1e7"))
        p.setPen(QPen(QColor("#b9a78a"), 2))
        p.drawRoundedRect(rect, 8, 8)
        mid = rect.center().y()
        p.setPen(QPen(QColor("#8a6d3b"), 3))
        p.drawLine(QPointF(rect.left() + 12, mid), QPointF(rect.right() - 12, mid))
        font = QFont(self.font())
        font.setPointSizeF(self.font_pt)
        p.setFont(font)
        p.setPen(QColor("#555"))
        words = rect.adjusted(16, 10, -16, -10)
        p.drawText(words, Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignHCenter,
                   HINT_BOWING if self.bowing else HINT)
        if self.bowing and self.target is not None:
            x = self._pixel(max(-REACH, min(REACH, self.target)))
            grip = QRectF(x - 14, mid - 34, 28, 68)
            p.setPen(QPen(QColor("#06c"), 2))
            p.setBrush(QColor(0, 102, 204, 90))
            p.drawRoundedRect(grip, 10, 10)
        p.end()
