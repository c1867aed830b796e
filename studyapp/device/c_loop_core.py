"""The C core of a version 2 device that runs the loop itself: firmware/studyapp_device.c with
studyapp_device_loop.c and the loop (studyapp_loop.c, the estimators), through ctypes.

``CLoopCore(info, loop)`` is ``c_core.CCore`` (rx, sample, actuate, tx, ...)
for an INFO whose loop section says loop = 1, with the C loop ``loop``
(``c_loop.CLoop`` over the loop's own arrays) attached (``sd_attach_loop``):
``sample`` applies the CONTROL settings due and runs the loop on the sample,
``actuate`` applies the safety core to the loop's force and queues TELEMETRY
(docs/device-protocol.md, "Version 2"). ``needs_alive`` is the lock-step's
wait: the device has run up to ALIVE's seen + START's latency.
"""

import ctypes

from studyapp.device import c_core, c_loop
from studyapp.device.c_core import BuildError, CCore

NAME = "studyapp_device_loop"
SOURCES = c_core.SOURCES + ("studyapp_device_loop.c", "studyapp_device_loop.h")
LOOP_COUNTERS = ("control", "queued", "seen", "loop_fault")

_LIB = None


def build():
    """The path of the device core and the loop in one library (built on first use, then cached)."""
    return c_core.build_library(NAME, SOURCES + tuple(s for s in c_loop.sources() if s not in SOURCES))


def library():
    global _LIB
    if _LIB is None:
        try:
            lib = c_core._load(build())
        except OSError as exc:
            raise BuildError(f"cannot load the C device loop: {exc}") from None
        ptr = ctypes.c_void_p
        lib.sd_attach_loop.argtypes = [ptr, ctypes.POINTER(c_loop.SlLoop)]
        lib.sd_attach_loop.restype = ctypes.c_int
        lib.sd_needs_alive.argtypes = [ptr]
        lib.sd_needs_alive.restype = ctypes.c_int
        lib.sd_loop_counters.argtypes = [ptr, ctypes.POINTER(ctypes.c_uint32 * 4)]
        _LIB = lib
    return _LIB


class CLoopCore(CCore):
    """The C core of ``info`` (a device loop's INFO) with the C loop ``loop`` (a c_loop.CLoop) attached."""

    def __init__(self, info, loop):
        super().__init__(info, library())
        self.loop = loop  # keeps the sl_loop and the arrays it points into alive
        if self._lib.sd_attach_loop(self._state, ctypes.byref(loop._loop)) != 0:
            raise BuildError("the C core refused the loop: INFO has no device loop, or other estimators")
        self._loop_counters = (ctypes.c_uint32 * 4)()

    def needs_alive(self):
        return bool(self._lib.sd_needs_alive(self._state))

    def counters(self):
        self._lib.sd_loop_counters(self._state, ctypes.byref(self._loop_counters))
        return {**super().counters(), **dict(zip(LOOP_COUNTERS, self._loop_counters))}
