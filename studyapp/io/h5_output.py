"""An HDF5 output written whole or not at all, a full disk reported as one error naming the file.

HDF5 keeps what it writes in its caches and writes it out when it evicts a
chunk or closes the file. A write that fails there (a full disk, ENOSPC, or a
file size limit, EFBIG) surfaced inside h5py's destructors as tracebacks it
cannot raise ("Exception ignored in ... Can't decrement id ref count"), then
as a crash, leaving the named temporary behind (issue 30, item 4).

So HDF5 writes here through a Python file object (h5py's ``fileobj`` driver)
that keeps the first ``OSError`` and drops every write after it: HDF5 never
sees a failure and closes cleanly, and ``H5Output`` then raises the kept error
with the target's name; the temporary (``atomic.atomic_path``) is removed, so
nothing is left. ``check()`` raises it as soon as it is known, so a streaming
writer stops at the next block. The file on disk is HDF5 as any driver writes it.
"""

import contextlib

from studyapp.io.atomic import atomic_path


class _Sink:
    """The temporary HDF5 writes to: the first failure is kept in ``error`` and later writes are dropped."""

    def __init__(self, path):
        self.file = open(path, "w+b", buffering=0)  # unbuffered: a failed write fails at once, not at a flush
        self.error = None

    def _guard(self, op, *args):
        if self.error is None:
            try:
                return op(*args)
            except OSError as exc:
                self.error = exc
        return None

    def write(self, data):
        view = memoryview(data).cast("B")
        done = 0
        while self.error is None and done < len(view):
            done += self._guard(self.file.write, view[done:]) or 0
        return len(view)

    def truncate(self, size):
        self._guard(self.file.truncate, size)
        return size

    def flush(self):
        self._guard(self.file.flush)

    def read(self, n=-1):
        return self.file.read(n)

    def seek(self, offset, whence=0):
        return self.file.seek(offset, whence)

    def tell(self):
        return self.file.tell()

    def close(self):
        self.file.close()


class H5Output:
    """``with H5Output(path) as out:`` write to ``out.file`` (an ``h5py.File``); ``path`` appears on success only."""

    def __init__(self, path):
        self.path = path
        self._stack = contextlib.ExitStack()

    def __enter__(self):
        import h5py

        try:
            tmp = self._stack.enter_context(atomic_path(self.path))
            self._sink = _Sink(tmp)
            self._stack.callback(self._sink.close)
            self.file = h5py.File(self._sink, "w")
        except BaseException as exc:
            self._stack.__exit__(type(exc), exc, exc.__traceback__)
            raise
        return self

    def check(self):
        """Raise the write failure met so far (an ``OSError`` naming the output), if any."""
        error = self._sink.error
        if error is not None:
            raise OSError(error.errno, error.strerror or str(error), str(self.path)) from error

    def __exit__(self, exc_type, exc, tb):
        try:
            self.file.close()  # cannot fail on the disk: the sink drops what it cannot write
            self.check()  # the disk's failure before any error it caused (HDF5 reading back a dropped write)
        except BaseException as error:
            if self._stack.__exit__(type(error), error, error.__traceback__):
                return True
            raise
        return self._stack.__exit__(exc_type, exc, tb)
