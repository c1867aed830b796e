"""Where the participant's window goes, and where the participant's pointer may go, beside the console.

One pointer serves two people when the participant bows with the mouse: a
click on the console while the participant bows ended the bow, and on one
screen the participant's full-screen window covered Resume and the EMERGENCY
STOP (issue 31 item 7).

- **One screen** (the participant's window asked for the console's own
  screen): it is not made full-screen; it fills the screen's available area
  right of the console's left column, so the set-up, the progress and the
  session buttons (Start, Pause/Resume, Abort, EMERGENCY STOP) stay in view
  and reachable (``beside_console``).
- **Two screens**: while a trial runs (the session's state ``running``) the
  pointer is kept on the participant's screen: each console tick (10 ms)
  moves it back inside the participant's window if it left (``confine``).
  Esc (the emergency stop, from either keyboard) frees it at once, as does
  any state but ``running`` (paused, stopped, finished). The limit: Qt can
  only move the pointer back after the fact (no grab confines it), and
  ``QCursor.setPos`` does nothing on Wayland, where the pointer is not
  confined at all; a second mouse is the same pointer under X11 too. The
  experimenter reaches the console by pressing Esc (the emergency stop) on
  either keyboard: the pointer is free from then on.
"""

from PySide6.QtCore import QPoint, QRect, Qt
from PySide6.QtGui import QCursor


def same_screen(participant, console):
    return participant.screen() is not None and participant.screen() is console.screen()


def beside_console(participant, console, left_column):
    """Place ``participant`` over the console's screen right of ``left_column`` (a widget of the console)."""
    area = console.screen().availableGeometry()
    right = left_column.mapToGlobal(QPoint(left_column.width(), 0)).x() + 1
    participant.setWindowState(participant.windowState() & ~Qt.WindowState.WindowFullScreen)
    participant.setGeometry(QRect(right, area.y(), max(1, area.right() - right + 1), area.height()))


def place(console, screen):
    """The participant's window full-screen on ``screen``, or beside the console's left column on its own."""
    participant = console.participant_window
    if screen is console.screen():
        participant.show()
        beside_console(participant, console, console.left_column)
    else:
        participant.show_full_screen(screen)


def clamped(point, rect):
    """``point`` moved inside ``rect`` (QPoint, QRect)."""
    return QPoint(min(max(point.x(), rect.left()), rect.right()), min(max(point.y(), rect.top()), rect.bottom()))


def confine(participant, console, running):
    """Keep the pointer in the participant's full-screen window on its own screen while ``running``."""
    if not (running and participant.isVisible() and participant.isFullScreen()) or same_screen(participant, console):
        return False
    rect = participant.frameGeometry()
    position = QCursor.pos()
    if rect.contains(position):
        return False
    QCursor.setPos(clamped(position, rect))
    return True
