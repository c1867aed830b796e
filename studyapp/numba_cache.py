"""Where numba keeps compiled code, keyed by the source that compiled it.

numba's ``cache=True`` checks only the timestamp of the file that defines a
function. A compiled function that inlines kernels from other files (the
estimator dispatch, the closed loop) would keep running stale machine code
after one of those files changed. So the cache directory is named after a hash
of every studyapp source file that holds compiled code: change any of them and
everything is compiled afresh, once.

``NUMBA_CACHE_DIR`` is read when numba is first imported, so ``configure()``
runs from ``studyapp/__init__.py``, before any layer imports numba, and worker
processes inherit it through the environment. A directory set by the user is
respected.
"""

import hashlib
import os
import shutil
import time
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
STALE_SECONDS = 24 * 3600


def source_hash():
    digest = hashlib.sha1()
    for path in sorted(PACKAGE.rglob("*.py")):
        data = path.read_bytes()
        if b"njit" in data:
            digest.update(str(path.relative_to(PACKAGE)).encode())
            digest.update(data)
    return digest.hexdigest()[:16]


def configure():
    if "NUMBA_CACHE_DIR" in os.environ:
        return
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "studyapp" / "numba"
    target = base / source_hash()
    if not target.exists():
        # builds of older source are dead weight once nothing has used them for a day;
        # a younger one may belong to a process still running the older code
        if base.exists():
            for old in base.iterdir():
                if time.time() - old.stat().st_mtime > STALE_SECONDS:
                    shutil.rmtree(old, ignore_errors=True)
        target.mkdir(parents=True, exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(target)
