"""Which screen the participant's window fills: ``--participant-screen N``, remembered per machine.

``choose_screen(N)`` returns ``QGuiApplication.screens()[N]`` (N from 0) and
remembers N in the machine's settings (``QSettings`` of organisation and
application "studyapp", key ``participant/screen``), so the next launch with
``--participant-window`` alone uses the same screen. An N the machine does
not have is a ``UserError`` naming it and the screens there are.
``choose_screen(None)`` returns the remembered screen, or None (no choice
made, or that screen is gone: the window then opens as an ordinary window).
"""

from PySide6.QtCore import QSettings
from PySide6.QtGui import QGuiApplication

from studyapp.errors import UserError

SETTINGS_KEY = "participant/screen"


def settings():
    return QSettings("studyapp", "studyapp")


def describe_screens(screens):
    return ", ".join(f"{i} = {s.name() or 'unnamed'} {s.geometry().width()}x{s.geometry().height()}"
                     for i, s in enumerate(screens))


def remembered_screen():
    """The index remembered on this machine, or None."""
    value = settings().value(SETTINGS_KEY)
    try:
        return int(value)
    except (TypeError, ValueError):
        return None


def choose_screen(index=None):
    """The ``QScreen`` for ``--participant-screen index`` (remembered), or the remembered one for None."""
    screens = QGuiApplication.screens()
    if index is None:
        index = remembered_screen()
        return screens[index] if index is not None and 0 <= index < len(screens) else None
    if not 0 <= index < len(screens):
        raise UserError(f"--participant-screen {index}: allowed is 0 to {len(screens) - 1} "
                        f"(the screens here: {describe_screens(screens)})")
    store = settings()
    store.setValue(SETTINGS_KEY, index)
    store.sync()
    return screens[index]
