"""Where an output was made: the software and the machine, one owner for every output.

``environment()`` is what recordings' metadata, ``session.json`` and the evaluation commands' JSON and
PARAMS.toml record (each calls it; none lists versions of its own): a flat dict of strings,

- ``studyapp_version`` and ``studyapp_commit`` (the git commit of the source tree the package was
  imported from, ``-dirty`` when tracked files differ from it; ``unknown`` outside a git checkout);
- ``python_version`` and ``<distribution>_version`` for each of ``PACKAGES`` (numpy, scipy, numba,
  llvmlite, pandas, ...), as installed (``importlib.metadata``: what ``requirements.lock`` pins);
- ``machine`` (``platform.machine()``) and ``cpu_model`` (``/proc/cpuinfo``'s "model name");
- ``numpy_blas`` and ``scipy_blas``: the OpenBLAS each of them runs, with the kernels it chose for this
  CPU, and ``numpy_simd``, the CPU features numpy's own loops dispatch to;
- ``env_STUDYAPP_...``: each studyapp setting taken from the environment, as set (``STUDYAPP_NUDGE``
  among them, which starts a simulation one rounding step off rest: an output made so must say so).

Why the BLAS at run time: OpenBLAS built with DYNAMIC_ARCH picks its kernels by CPU (or by
``OPENBLAS_CORETYPE``), and what goes through BLAS differs in the last bits from one kernel set to
another (issue 39). ``numpy.show_config()`` names the library numpy was built against, but its
"openblas configuration" names the build machine's core, not this one's; the core in use is asked of
the loaded library (``openblas_get_config``, with the symbol prefix and suffix of the scipy-openblas
wheels). Where that cannot be asked (another BLAS, another OS), the build's name and version are
recorded with ``(kernels unknown)``.

The result is computed once per process: the code, libraries and CPU of a process do not change.
"""

import ctypes
import functools
import importlib.metadata
import os
import platform
import subprocess
from pathlib import Path

from studyapp import __version__

PACKAGES = (
    "numpy", "scipy", "numba", "llvmlite", "pandas", "h5py", "matplotlib", "mido", "python-rtmidi",
    "sounddevice", "pyserial", "PySide6-Essentials", "pyqtgraph",
)
SOURCE = Path(__file__).resolve().parent.parent  # the folder holding the studyapp package
GIT_TIMEOUT = 10  # seconds: a git that hangs (a lock, a network file system) costs one output this much at most
_CONFIG_SYMBOLS = ("scipy_openblas_get_config64_", "scipy_openblas_get_config", "openblas_get_config64_",
                   "openblas_get_config")


def environment():
    """The flat dict of strings the module docstring lists: a copy of the process's, the caller's to keep."""
    return dict(_environment())


@functools.lru_cache(maxsize=1)
def _environment():
    info = {"studyapp_version": __version__, "studyapp_commit": commit(SOURCE),
            "python_version": platform.python_version()}
    for name in PACKAGES:
        info[f"{name.lower().replace('-', '_')}_version"] = _installed(name)
    info["machine"] = platform.machine()
    info["cpu_model"] = cpu_model()
    info.update(blas())
    info.update({f"env_{name}": value for name, value in sorted(os.environ.items()) if name.startswith("STUDYAPP_")})
    return info


def _installed(name):
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def commit(folder):
    """The commit of the git checkout at ``folder`` (``-dirty`` if tracked files changed), else ``unknown``.

    Only a checkout whose top is ``folder`` itself counts: a package installed into a venv that lies
    inside some repository is not that repository's code."""
    if not (folder / ".git").exists():
        return "unknown"
    try:
        head = _git(folder, "rev-parse", "HEAD")
        changed = _git(folder, "status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head + ("-dirty" if changed else "")


def _git(folder, *args):
    done = subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True, timeout=GIT_TIMEOUT,
                          stdin=subprocess.DEVNULL, check=True)
    return done.stdout.strip()


def cpu_model(cpuinfo=Path("/proc/cpuinfo")):
    """The first "model name" of ``/proc/cpuinfo`` (Linux on x86), else what ``platform`` says."""
    try:
        for line in cpuinfo.read_text(errors="replace").splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name":
                return value.strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def blas():
    """``numpy_blas``, ``scipy_blas`` (the OpenBLAS each runs, kernels included) and ``numpy_simd``."""
    import numpy
    import scipy
    import scipy.linalg  # loads scipy's own OpenBLAS

    loaded = _loaded_libraries()
    info = {}
    for module in (numpy, scipy):
        name = module.__name__
        own = [p for p in loaded if f"{os.sep}{name}.libs{os.sep}" in p]  # a wheel's bundled library
        shared = [p for p in loaded if ".libs" + os.sep not in p]  # a system library both link to
        runtime = [_runtime_config(p) for p in own or shared]
        runtime = [text for text in runtime if text]
        info[f"{name}_blas"] = "; ".join(runtime) if runtime else _build_blas(module) + " (kernels unknown)"
    simd = numpy.show_config(mode="dicts").get("SIMD Extensions", {})
    info["numpy_simd"] = " ".join(simd.get("found", [])) or "none found"
    return info


def _loaded_libraries():
    """Paths of the OpenBLAS libraries mapped into this process (Linux: ``/proc/self/maps``), else ()."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        return ()
    paths = {line.split(None, 5)[5] for line in maps.splitlines() if len(line.split(None, 5)) == 6}
    return sorted(p for p in paths if "openblas" in Path(p).name.lower())


def _runtime_config(path):
    """What the library at ``path`` says of itself (version, build options, the core in use), or None."""
    try:
        library = ctypes.CDLL(path)
    except OSError:
        return None
    for symbol in _CONFIG_SYMBOLS:
        function = getattr(library, symbol, None)
        if function is not None:
            function.restype = ctypes.c_char_p
            return " ".join(function().decode(errors="replace").split())
    return None


def _build_blas(module):
    """The BLAS ``module`` was built against, by ``show_config``: name and version."""
    try:
        config = module.show_config(mode="dicts")["Build Dependencies"]["blas"]
    except (KeyError, TypeError, ValueError):
        return "unknown"
    return f"{config.get('name', 'unknown')} {config.get('version', '')}".strip()
