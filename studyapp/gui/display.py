"""Is there a screen for Qt? Checked before Qt is imported.

Without one, Qt's platform plugin aborts the process (exit 134, several lines
of plugin errors); the user should get one line and exit code 2 instead.
"""

import os
import sys

from studyapp.errors import UserError


def require_display():
    if (sys.platform.startswith("linux") and not os.environ.get("QT_QPA_PLATFORM")
            and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")):
        raise UserError("no display (DISPLAY is not set): allowed is a desktop session, QT_QPA_PLATFORM=offscreen "
                        "(e.g. with --screenshot), or 'studyapp run ... --simulated-participant --headless'")
