"""Capture what C libraries print on file descriptor 2 while probing for devices.

ALSA, JACK and PortAudio print several lines to fd 2 when no sound card, no
sequencer or no JACK server exists ("ALSA lib seq_hw.c: ... open /dev/snd/seq
failed", "Cannot connect to server socket", ...). The user should see one line
saying what is missing and what the engine does instead, so probes run inside
``captured_native_stderr()``, which points fd 2 at a temporary file and gives the
text back (``.text``) for a log or an error message.
"""

import contextlib
import os
import sys
import tempfile


class Captured:
    text = ""


@contextlib.contextmanager
def captured_native_stderr():
    """Redirect fd 2 (and ``sys.stderr``'s buffer) to a temporary file for the block."""
    captured = Captured()
    with contextlib.suppress(AttributeError, ValueError):
        sys.stderr.flush()
    try:
        saved = os.dup(2)
    except OSError:
        yield captured
        return
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield captured
        finally:
            with contextlib.suppress(AttributeError, ValueError):
                sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            captured.text = tmp.read().decode("utf-8", "replace")
