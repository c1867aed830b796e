"""A pseudo-terminal whose device end is reachable at a path of the user's choosing, as socat makes one.

``PtyLink(path)`` opens a pty (os.openpty), puts its line discipline in raw
mode (no echo, no line editing, no CR/LF translation: every byte as sent)
and makes ``path`` a symbolic link to the device end (/dev/pts/N), which a
host opens as it would a serial port. The emulator keeps both ends open, so
a host may close and reopen the port; it reads and writes the controller
end, non-blocking.

``path`` is never replaced unless it is a stale link of a previous emulator
(a link to a /dev/pts/N that no longer exists); anything else there is
refused. ``close`` removes the link if it still points to this pty.
"""

import errno
import os
import tty

from studyapp.errors import UserError

PENDING_MAX = 1 << 16  # bytes waiting for the host to read, beyond which frames are dropped


def stale(path):
    """``path`` is a link to a pseudo-terminal that no longer exists."""
    if not os.path.islink(path):
        return False
    target = os.readlink(path)
    return target.startswith("/dev/pts/") and not os.path.exists(target)


def check_path(path):
    """``UserError`` unless ``path`` can become the link: its folder exists, nothing but a stale link is there."""
    path = os.path.abspath(path)
    parent = os.path.dirname(path)
    if not os.path.isdir(parent):
        raise UserError(f"--link {path}: the folder {parent} does not exist")
    if os.path.lexists(path) and not stale(path):
        raise UserError(f"--link {path}: exists and is not a stale link of a device emulator (allowed: a new path)")
    return path


class PtyLink:
    """The pty and the link to it; ``read()`` what the host sent, ``write(data)`` to it."""

    def __init__(self, path):
        self.path = os.path.abspath(path)
        self.master = self.slave = None
        self.name = None
        self._pending = bytearray()
        self.dropped = 0

    def open(self):
        check_path(self.path)
        if os.path.lexists(self.path):
            os.unlink(self.path)
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        os.set_blocking(self.master, False)
        self.name = os.ttyname(self.slave)
        try:
            os.symlink(self.name, self.path)
        except OSError as exc:
            self._close_fds()
            raise UserError(f"--link {self.path}: cannot make the link ({exc.strerror})") from None
        return self

    def read(self):
        try:
            return os.read(self.master, 1 << 16)
        except BlockingIOError:
            return b""
        except OSError as exc:
            if exc.errno == errno.EIO:  # no process has the device end open
                return b""
            raise

    def write(self, data):
        """Queue ``data`` for the host and write what the pty takes now; a full queue drops ``data``."""
        if data:
            if len(self._pending) + len(data) > PENDING_MAX:
                self.dropped += 1
            else:
                self._pending += data
        if self._pending:
            try:
                n = os.write(self.master, self._pending)
            except (BlockingIOError, InterruptedError):
                return
            del self._pending[:n]

    @property
    def pending(self):
        return len(self._pending)

    def _close_fds(self):
        for fd in (self.master, self.slave):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self.master = self.slave = None

    def close(self):
        try:
            if os.path.islink(self.path) and os.readlink(self.path) == self.name:
                os.unlink(self.path)
        except OSError:
            pass
        self._close_fds()

    def __enter__(self):
        return self.open()

    def __exit__(self, *exc):
        self.close()
