"""Where numba keeps compiled code, keyed by the source that compiled it, wherever that source lies.

numba's ``cache=True`` checks only the contents of the file that defines a
function. A compiled function that inlines kernels from other files (the
estimator dispatch, the closed loop) would keep running stale machine code
after one of those files changed. So the cache directory is named after a hash
of every studyapp source file that holds compiled code (paths relative to the
package, and contents): change any of them and everything is compiled afresh,
once.

Inside that directory numba puts each file's index and code in a folder named
after a SHA-1 of the file's *absolute* folder (``get_suitable_cache_subpath``):
a second clone of the same sources (another checkout, a worktree, CI's fresh
clone) looked in folders of its own, found nothing and compiled every kernel
again (704 s under load, issue 31). ``PackageLocator`` names the folder after
the file's folder *relative to the package* instead (``model``,
``estimators``, ...), so any clone with the same sources finds the same cache.
Nothing else in numba's key depends on the path: the index is checked against
a SHA-256 of the file's contents (numba 0.59 on; older numba used the file's
modification time, which a clone also changes) and its entries are keyed by
signature, target and the function's bytecode. Files outside the package get
numba's own locators.

``NUMBA_CACHE_DIR`` and ``NUMBA_CACHE_LOCATOR_CLASSES`` are read when numba
is first imported, so ``configure()`` runs from ``studyapp/__init__.py``,
before any layer imports numba, and worker processes inherit both through the
environment. A directory set by the user is respected (and numba's own
locators with it).
"""

import functools
import hashlib
import os
import shutil
import time
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
STALE_SECONDS = 24 * 3600
LOCATOR = f"{__name__}.PackageLocator"


def source_hash():
    digest = hashlib.sha1()
    for path in sorted(PACKAGE.rglob("*.py")):
        data = path.read_bytes()
        if b"njit" in data:
            digest.update(str(path.relative_to(PACKAGE)).encode())
            digest.update(data)
    return digest.hexdigest()[:16]


def relative_folder(py_file, package=PACKAGE):
    """The folder of ``py_file`` relative to the folder above ``package`` (``studyapp/model``); None outside it."""
    try:
        inside = Path(py_file).resolve().parent.relative_to(package)
    except ValueError:
        return None
    return (Path(package.name) / inside).as_posix()


@functools.cache
def _package_locator():
    """numba's user-directory locator, with the file's folder named relative to the package (numba imported late)."""
    from numba.core import caching, config

    class PackageLocator(caching.UserProvidedCacheLocator):
        def __init__(self, py_func, py_file):
            super().__init__(py_func, py_file)
            self._cache_path = os.path.join(config.CACHE_DIR, relative_folder(py_file))

        @classmethod
        def from_function(cls, py_func, py_file):
            if config.CACHE_DIR and relative_folder(py_file) is not None:
                return super().from_function(py_func, py_file)
            impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # renamed in numba 0.68
            for other in impl._locator_classes:  # numba's own, in numba's order
                if issubclass(other, cls):
                    continue
                locator = other.from_function(py_func, py_file)
                if locator is not None:
                    return locator
            return None

    return PackageLocator


def __getattr__(name):
    # numba resolves NUMBA_CACHE_LOCATOR_CLASSES by importing this module and reading the class
    if name == "PackageLocator":
        return _package_locator()
    raise AttributeError(name)


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
    os.environ.setdefault("NUMBA_CACHE_LOCATOR_CLASSES", LOCATOR)
