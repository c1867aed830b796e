"""A real device behind a byte link: the protocol's codec, the device-side safety core and the emulator.

docs/device-protocol.md is the protocol a lab implements in firmware. The
files, one idea each: ``cobs.py`` and ``crc.py`` (the byte stuffing and the
check), ``frames.py`` (payload <-> wire bytes, a streaming reader),
``messages.py`` (the message types), ``streams.py`` (sequence numbers and
counters of one direction), ``device_side.py`` (the safety core a firmware
must have), ``firmware.py`` (the firmware's loop around it: bytes in, a
sample, bytes out), ``c_core.py`` (the same loop in C,
firmware/studyapp_device.c, built and loaded), ``c_estimators.py`` and
``c_loop.py`` (the estimators and the haptic loop in C, for a device that
closes the loop itself; docs/device-loop.md), ``loop_benchmark.py`` (the
loop's cost in C and in numba), ``pty_link.py``, ``link_faults.py`` and
``emulator.py`` (a device on a pty). No module here is compiled by numba.
"""
