"""Opening a device link: a serial port or pty path, or a pyserial URL, never a hang.

A link is named by a path (``/dev/ttyACM0``, a pty, or a symbolic link to one,
as ``studyapp device-emulator --link PATH`` makes) or a URL (anything with
``://``, for pyserial's ``serial_for_url``: ``socket://127.0.0.1:PORT``).

Before pyserial touches a path it is opened here with ``O_NONBLOCK`` (an open
of a FIFO with no writer, or of a serial port waiting for carrier, would
otherwise block) and checked to be a character device: a regular file, a
FIFO, a directory or a socket gets one line naming the path and what it is.
A ``socket://`` URL is first connected with ``CONNECT_TIMEOUT`` (pyserial's
own is 5 s), so an address that never answers fails in time.

``Transport`` is the open link as the driver uses it: non-blocking
``read()`` (the bytes there now), ``write(data)`` (all of it, or an
``OSError``), ``wait(timeout)`` (readable?) and ``close()``. A path is read
and written through its file descriptor (``os.read`` / ``os.write``, the
cheapest path per frame), a socket through the socket, any other URL through
pyserial's own ``read``/``write``.
"""

import errno
import os
import select
import socket
import stat
import time

from studyapp.errors import ParameterError

CONNECT_TIMEOUT = 1.0  # s for a socket:// URL to accept the connection
WRITE_TIMEOUT = 0.02  # s a write may wait for room before the link counts as stuck
READ_CHUNK = 1 << 16


def is_link(spec):
    """True when ``spec`` names a link (a path or a URL) rather than a ``"module:factory"`` driver."""
    if not isinstance(spec, str) or not spec:
        return False
    if "://" in spec or spec.startswith(("/", ".", "~")):
        return True
    module, colon, factory = spec.partition(":")
    return not (colon and module and factory and all(p.isidentifier() for p in module.split(".") + [factory]))


def _kind(mode):
    for test, word in ((stat.S_ISREG, "a regular file"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISDIR, "a directory"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISBLK, "a block device")):
        if test(mode):
            return word
    return "not a character device"


def check_path(path):
    """``ParameterError`` unless ``path`` is a character device that opens for reading and writing now."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_NONBLOCK | os.O_NOCTTY)
    except FileNotFoundError:
        raise ParameterError(f"--device {path}: no such file; allowed is a serial port, a pty or a pyserial URL "
                             "(socket://HOST:PORT)") from None
    except OSError as exc:
        kind = ""
        try:
            kind = f" ({_kind(os.stat(path).st_mode)})"
        except OSError:
            pass
        raise ParameterError(f"--device {path}{kind}: cannot be opened ({exc.strerror}); allowed is a serial port, "
                             "a pty or a pyserial URL") from None
    try:
        mode = os.fstat(fd).st_mode
    finally:
        os.close(fd)
    if not stat.S_ISCHR(mode):
        raise ParameterError(f"--device {path}: {_kind(mode)}, not a device; allowed is a serial port, a pty "
                             "or a pyserial URL (socket://HOST:PORT)")


def _check_socket_url(url):
    address = url.split("://", 1)[1].split("?", 1)[0].rstrip("/")
    host, _, port = address.rpartition(":")
    try:
        port = int(port)
    except ValueError:
        raise ParameterError(f"--device {url}: allowed is socket://HOST:PORT with a port number") from None
    try:
        socket.create_connection((host or "localhost", port), timeout=CONNECT_TIMEOUT).close()
    except OSError as exc:
        raise ParameterError(f"--device {url}: nothing answers there ({exc.strerror or exc}); "
                             "allowed is a listening device link") from None


class Transport:
    """An open link: non-blocking reads, bounded writes."""

    def __init__(self, spec, port, fd, sock):
        self.spec = spec
        self.port = port  # the pyserial object (kept open; it owns the descriptor)
        self._fd = fd
        self._sock = sock

    def fileno(self):
        return self.port.fileno()

    def wait(self, timeout):
        """True when bytes can be read within ``timeout`` s (or the link has closed: the read says so)."""
        ready, _, _ = select.select([self.fileno()], [], [], max(0.0, timeout))
        return bool(ready)

    def read(self):
        """The bytes there now (b"" if none); ``OSError`` (EIO, ECONNRESET, ...) or ``EOFError`` once the link is gone."""
        if self._fd is not None:
            try:
                data = os.read(self._fd, READ_CHUNK)
            except BlockingIOError:
                return b""
            if not data and select.select([self._fd], [], [], 0)[0]:
                # a tty with VMIN 0 reads b"" when empty, and bytes may have come since: read again; b"" while
                # it polls readable is a port that went away (hung up)
                try:
                    data = os.read(self._fd, READ_CHUNK)
                except BlockingIOError:
                    return b""
                if not data:
                    raise EOFError("the link closed")
            return data
        if self._sock is not None:
            try:
                data = self._sock.recv(READ_CHUNK, socket.MSG_DONTWAIT)
            except BlockingIOError:
                return b""
            if not data:
                raise EOFError("the link closed")
            return data
        return self.port.read(max(1, self.port.in_waiting))

    def write(self, data):
        """Write all of ``data``; ``OSError`` if the link will not take it within ``WRITE_TIMEOUT``."""
        view = memoryview(data)
        end = time.monotonic() + WRITE_TIMEOUT
        while view:
            try:
                if self._fd is not None:
                    sent = os.write(self._fd, view)
                elif self._sock is not None:
                    sent = self._sock.send(view, socket.MSG_DONTWAIT)
                else:
                    sent = self.port.write(bytes(view)) or 0
            except BlockingIOError:
                sent = 0
            view = view[sent:]
            if view:
                if time.monotonic() > end:
                    raise OSError(errno.ETIMEDOUT, "the link did not take a frame within "
                                                   f"{1e3 * WRITE_TIMEOUT:g} ms")
                select.select([], [self.fileno()], [], 0.001)

    def close(self):
        try:
            self.port.close()
        except (OSError, AttributeError):
            pass


def open_link(spec):
    """The ``Transport`` of the link ``spec`` (path or URL); ``ParameterError`` (one line) if it is not one."""
    import serial

    spec = str(spec)
    if "://" in spec:
        if spec.startswith("socket://"):
            _check_socket_url(spec)
        try:
            port = serial.serial_for_url(spec, timeout=0, write_timeout=WRITE_TIMEOUT)
        except (serial.SerialException, ValueError, OSError) as exc:
            raise ParameterError(f"--device {spec}: cannot be opened ({str(exc).splitlines()[0]})") from None
        sock = getattr(port, "_socket", None)
        if sock is not None:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        return Transport(spec, port, None, sock)
    path = os.path.expanduser(spec)
    check_path(path)
    try:
        port = serial.Serial(path, timeout=0, write_timeout=WRITE_TIMEOUT, exclusive=True)
    except (serial.SerialException, ValueError, OSError) as exc:
        raise ParameterError(f"--device {spec}: cannot be opened ({str(exc).splitlines()[0]})") from None
    return Transport(spec, port, port.fileno(), None)
