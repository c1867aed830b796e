"""Layout checks on a rendered window: what a screenshot test looks for.

``layout_problems(window)`` lists, one line each, every visible widget whose
rectangle (mapped into the window) extends past the window's, and every
label or button whose text needs more room than the widget gives it (clipped
text). A label that wraps is checked by the height its text needs at its
width; one that elides (``elide`` property set by the widget) is skipped.
Widgets inside a scroll area are left to it (it shows what overflows); the
scroll area itself is checked. An empty list means the window shows all of itself.
"""

from PySide6.QtCore import QRect, Qt
from PySide6.QtWidgets import QAbstractButton, QAbstractScrollArea, QLabel, QWidget


def _name(widget):
    name = widget.objectName() or type(widget).__name__
    text = widget.text() if isinstance(widget, (QLabel, QAbstractButton)) else ""
    return f"{name} {text[:40]!r}" if text else name


def _clipped(widget):
    """Why ``widget``'s text does not fit in it, or None."""
    if widget.property("elide"):
        return None
    if isinstance(widget, QLabel):
        text = widget.text()
        if not text or widget.textFormat() == Qt.TextFormat.RichText or "<" in text:
            return None  # rich text lays itself out; a scroll area shows what overflows
        room = widget.contentsRect()
        metrics = widget.fontMetrics()
        if widget.wordWrap():
            need = metrics.boundingRect(QRect(0, 0, max(room.width(), 1), 100000),
                                        int(Qt.TextFlag.TextWordWrap), text).height()
            return f"needs {need} px of height, has {room.height()}" if need > room.height() + 1 else None
        lines = text.splitlines() or [""]
        need_w = max(metrics.horizontalAdvance(line) for line in lines)
        need_h = metrics.height() * len(lines)
        if need_w > room.width() + 1:
            return f"needs {need_w} px of width, has {room.width()}"
        if need_h > room.height() + 1:
            return f"needs {need_h} px of height, has {room.height()}"
        return None
    if isinstance(widget, QAbstractButton) and widget.text():
        need = widget.fontMetrics().horizontalAdvance(widget.text().replace("&", ""))
        return f"needs {need} px of width, has {widget.width()}" if need > widget.width() else None
    return None


def _scrolled(widget, window):
    parent = widget.parentWidget()
    while parent is not None and parent is not window:
        if isinstance(parent, QAbstractScrollArea):
            return True
        parent = parent.parentWidget()
    return False


def layout_problems(window):
    """Lines naming each widget past ``window``'s edge or with clipped text (empty: none)."""
    problems = []
    frame = window.rect()
    for widget in window.findChildren(QWidget):
        if not widget.isVisibleTo(window) or widget.isWindow() or _scrolled(widget, window):
            continue
        top_left = widget.mapTo(window, widget.rect().topLeft())
        rect = QRect(top_left, widget.size())
        if not frame.contains(rect):
            problems.append(f"{_name(widget)} at {rect.getRect()} extends past the window {frame.getRect()}")
            continue
        why = _clipped(widget)
        if why:
            problems.append(f"{_name(widget)}: text clipped ({why})")
    return problems
