"""The bowing pad: drag with the mouse to bow the simulated device.

The pad's width is the handle's travel (the device's end stops at +-11 mm,
``studyapp.model.device.DeviceLimits``; the pad spans +-``REACH`` of it so the
hand stops short of them). Pressing the mouse puts the bow on the string and
makes the virtual hand hold the handle at the pointer (``bow_pressed(x)``,
x in metres); dragging moves the hand's target (``bow_moved(x)``) and so bows
the string; releasing lifts the bow (``bow_released``). The hand is a
mass-spring-damper (``studyapp.model.hand``), so the handle follows the
pointer smoothly even though the pointer arrives in jumps of one mouse event.

``show_handle(x)`` draws where the handle really is (from the telemetry), so
the experimenter sees the device follow, or not.
"""

from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPen
from PySide6.QtWidgets import QSizePolicy, QWidget

from studyapp.model.device import DeviceLimits

REACH = 0.9 * DeviceLimits().travel  # m either side of the centre


class BowingPad(QWidget):
    bow_pressed = Signal(float)
    bow_moved = Signal(float)
    bow_released = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumSize(220, 70)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.setCursor(Qt.CursorShape.OpenHandCursor)
        self.setToolTip("drag left and right to bow the simulated device")
        self.bowing = False
        self.target = None
        self.handle = None

    def position_at(self, px):
        """Metres for the pointer at ``px`` pixels from the left edge."""
        width = max(1, self.width() - 1)
        fraction = min(max(px / width, 0.0), 1.0)
        return (2.0 * fraction - 1.0) * REACH

    def _pixel(self, x_m):
        return (x_m / REACH + 1.0) / 2.0 * (self.width() - 1)

    def mousePressEvent(self, event):
        if event.button() != Qt.MouseButton.LeftButton:
            return
        self.bowing = True
        self.target = self.position_at(event.position().x())
        self.setCursor(Qt.CursorShape.ClosedHandCursor)
        self.bow_pressed.emit(self.target)
        self.update()

    def mouseMoveEvent(self, event):
        if not self.bowing:
            return
        self.target = self.position_at(event.position().x())
        self.bow_moved.emit(self.target)
        self.update()

    def mouseReleaseEvent(self, event):
        if event.button() != Qt.MouseButton.LeftButton or not self.bowing:
            return
        self.bowing = False
        self.setCursor(Qt.CursorShape.OpenHandCursor)
        self.bow_released.emit()
        self.update()

    def show_handle(self, x_m):
        self.handle = float(x_m)
        self.update()

    def paintEvent(self, event):
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        rect = QRectF(self.rect()).adjusted(1, 1, -1, -1)
        p.fillRect(rect, QColor("#f4efe6") if not self.bowing else QColor("#efe0c4"))
        p.setPen(QPen(QColor("#999"), 1))
        p.drawRect(rect)
        mid = rect.center().y()
        p.setPen(QPen(QColor("#8a6d3b"), 2))
        p.drawLine(QPointF(rect.left() + 6, mid), QPointF(rect.right() - 6, mid))
        p.setPen(QColor("#666"))
        text = "bowing: drag left/right" if self.bowing else "press and drag to bow"
        p.drawText(rect.adjusted(6, 4, -6, -4), Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft, text)
        p.drawText(rect.adjusted(6, 4, -6, -4), Qt.AlignmentFlag.AlignBottom | Qt.AlignmentFlag.AlignLeft,
                   f"-{REACH * 1e3:.0f} mm")
        p.drawText(rect.adjusted(6, 4, -6, -4), Qt.AlignmentFlag.AlignBottom | Qt.AlignmentFlag.AlignRight,
                   f"+{REACH * 1e3:.0f} mm")
        if self.handle is not None:
            x = self._pixel(max(-REACH, min(REACH, self.handle)))
            p.setPen(QPen(QColor("#1f77b4"), 3))
            p.drawLine(QPointF(x, mid - 14), QPointF(x, mid + 14))
        if self.bowing and self.target is not None:
            x = self._pixel(self.target)
            p.setPen(QPen(QColor("#d62728"), 1, Qt.PenStyle.DashLine))
            p.drawLine(QPointF(x, rect.top() + 2), QPointF(x, rect.bottom() - 2))
        p.end()
