"""Write files whole or not at all.

A command that fails half-way must not leave a half-written output behind, so
every output is written to a temporary file beside its target and renamed over
it only once complete (``os.replace`` is atomic on POSIX within a filesystem).
"""

import contextlib
import os
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path beside ``target``; rename it to ``target`` on success."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=target.suffix, dir=target.parent)
    # mkstemp makes the file private (0600); an output should get the usual
    # permissions, as open() would give it under the user's umask
    umask = os.umask(0)
    os.umask(umask)
    os.fchmod(fd, 0o666 & ~umask)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, target)
    except OSError as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if exc.filename is None:
            # a failed write (a full disk) names no file: name the output, so the one-line error can
            raise OSError(exc.errno, exc.strerror or str(exc), str(target)) from exc
        raise
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_open(target, mode="w", **kwargs):
    """Open a temporary file beside ``target``; it replaces ``target`` when closed without error."""
    with atomic_path(target) as tmp, open(tmp, mode, **kwargs) as f:
        yield f
