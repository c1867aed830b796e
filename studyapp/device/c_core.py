"""The C core (firmware/studyapp_device.c), built with the system's C compiler and run through ctypes.

The same interface as firmware.py's ``Firmware`` (rx, sample, needs_force,
actuate, tx, streaming, busy, counters), so the emulator runs either and the
tests hold the two equal byte for byte. ``build()`` compiles the C files
(``SOURCES``) once into the user's cache (``$XDG_CACHE_HOME/studyapp/device/<hash of the
sources and flags>/``, the compiler from ``$CC`` or ``cc``; the Debian
packages gcc and libc6-dev, scripts/system-deps.txt) and returns the shared
library's path; a second process finds it there. ``build_library`` does the
same for any set of firmware/ sources (the estimators: c_estimators.py).
C99, -O2, no contraction of a * b + c into a fused multiply-add
(``-ffp-contract=off``), so the floating point is the same as Python's and
numba's, operation for operation.
"""

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from studyapp.device.device_side import SafetyConfig

SOURCE_DIR = Path(__file__).resolve().parents[2] / "firmware"
SOURCES = ("studyapp_device.c", "studyapp_device_link.c", "studyapp_device.h", "studyapp_bytes.h")
FLAGS = ("-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-pedantic", "-Werror", "-fPIC", "-shared")
LIBS = ("-lm",)  # after the sources: the C maths library (sqrt, fabs, copysign, isfinite's kin)
COUNTERS = ("now", "armed", "streaming", "fault", "late", "lost", "corrupt", "missing")
TX_CHUNK = 1 << 14


class BuildError(RuntimeError):
    """The C core could not be built or loaded (one line)."""


def cache_dir():
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "studyapp" / "device"


def build():
    """The path of the compiled core, compiling it first if this version of the sources has none."""
    return build_library("studyapp_device", SOURCES)


def build_library(name, sources):
    """The path of the shared library ``name``.so built from ``sources`` (file names in firmware/), compiling it
    first if this version of the sources has none.

    Every ``.c`` of ``sources`` is compiled into the one library; every file of ``sources`` (headers too)
    goes into the hash that names its folder in the cache, with the compiler and ``FLAGS``.
    """
    missing = [s for s in sources if not (SOURCE_DIR / s).is_file()]
    if missing:
        raise BuildError(f"{SOURCE_DIR / missing[0]} not found (a source checkout of studyapp has it)")
    compiler = os.environ.get("CC") or "cc"
    if shutil.which(compiler) is None:
        raise BuildError(f"no C compiler {compiler!r} (install the Debian packages gcc and libc6-dev)")
    digest = hashlib.sha1(" ".join((compiler,) + FLAGS + LIBS).encode())
    for s in sources:
        digest.update((SOURCE_DIR / s).read_bytes())
    target = cache_dir() / digest.hexdigest()[:16] / f"{name}.so"
    if target.is_file():
        return target
    units = [s for s in sources if s.endswith(".c")]
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".so", dir=target.parent)
    os.close(fd)
    try:
        r = subprocess.run([compiler, *FLAGS, "-o", tmp, *(str(SOURCE_DIR / s) for s in units), *LIBS],
                           capture_output=True, text=True, timeout=120)
        if r.returncode != 0:
            first = (r.stderr.strip().splitlines() or ["no message"])[0]
            raise BuildError(f"{compiler} failed on {', '.join(units)}: {first}")
        os.replace(tmp, target)  # atomic: a process running at once loads a whole library or builds its own
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return target


def _load(path):
    lib = ctypes.CDLL(str(path))
    u32, f64, ptr, buf = ctypes.c_uint32, ctypes.c_double, ctypes.c_void_p, ctypes.c_char_p
    lib.sd_sizeof.restype = u32
    lib.sd_init.argtypes = [ptr, buf, u32, f64]
    lib.sd_init.restype = ctypes.c_int
    lib.sd_rx.argtypes = [ptr, buf, u32]
    lib.sd_sample.argtypes = [ptr, ctypes.POINTER(f64)]
    lib.sd_needs_force.argtypes = [ptr]
    lib.sd_needs_force.restype = ctypes.c_int
    lib.sd_actuate.argtypes = [ptr]
    lib.sd_actuate.restype = f64
    lib.sd_tx.argtypes = [ptr, ptr, u32]
    lib.sd_tx.restype = u32
    lib.sd_counters.argtypes = [ptr, ctypes.POINTER(u32 * 8)]
    lib.sd_set_counter.argtypes = [ptr, u32]
    lib.sd_crc16.argtypes = [buf, u32, ctypes.c_uint16]
    lib.sd_crc16.restype = ctypes.c_uint16
    return lib


_LIB = None


def library():
    global _LIB
    if _LIB is None:
        try:
            _LIB = _load(build())
        except OSError as exc:
            raise BuildError(f"cannot load the C core: {exc}") from None
    return _LIB


class CCore:
    """The C firmware core for the device described by ``info`` (messages.Info); ``lib``: a library built with it."""

    def __init__(self, info, lib=None):
        self.info = info
        self._lib = lib or library()
        self._state = ctypes.create_string_buffer(self._lib.sd_sizeof())
        payload = info.pack(0)
        alpha = SafetyConfig.from_info(info).rms_alpha
        if self._lib.sd_init(self._state, payload, len(payload), alpha) != 0:
            raise BuildError("the C core refused the INFO message")
        self._raw = (ctypes.c_double * len(info.channels))()
        self._out = ctypes.create_string_buffer(TX_CHUNK)
        self._counters = (ctypes.c_uint32 * 8)()

    def rx(self, data):
        data = bytes(data)
        self._lib.sd_rx(self._state, data, len(data))

    def sample(self, raw):
        for i, v in enumerate(raw):
            self._raw[i] = v
        self._lib.sd_sample(self._state, self._raw)

    def needs_force(self):
        return bool(self._lib.sd_needs_force(self._state))

    def actuate(self):
        return self._lib.sd_actuate(self._state)

    def tx(self):
        chunks = []
        while True:
            n = self._lib.sd_tx(self._state, self._out, TX_CHUNK)
            if not n:
                return b"".join(chunks)
            chunks.append(self._out.raw[:n])

    def set_counter(self, sample):
        """The sample counter from ``sample`` (u32) on: before START (the emulator's --first-sample)."""
        self._lib.sd_set_counter(self._state, sample & 0xFFFFFFFF)

    def counters(self):
        self._lib.sd_counters(self._state, ctypes.byref(self._counters))
        return dict(zip(COUNTERS, self._counters))

    @property
    def now(self):
        return self.counters()["now"]

    def streaming(self):
        return bool(self.counters()["streaming"])

    def busy(self):
        c = self.counters()
        return bool(c["streaming"] or c["armed"])
