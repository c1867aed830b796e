"""The closed loop on a device that runs it: the emulator (``device-emulator --loop device --lockstep``) in its own
process behind a pty, and the host's ``LoopLink`` with its shadow, as one ``ClosedLoop`` for the breakdown search.

The paper closed its loop on the device (Sec. 8.4): the force for sample k
from the sensors of sample k. Here the emulator's C loop does that on its
simulated device (the hand's gesture and the sensors' noise drawn by
``seed``, as the model's simulated device draws them), and the host follows
it row by row (loop_link.py): its settings (source, F_max) reach the device
as a CONTROL ``late`` samples after a full telemetry packet (the lock-step
lead ``packet + late``: the device runs no further than that past the rows
the host has read), the force never crosses the link. The host's loop
carries every estimator the device runs (INFO's list, Table 1 at the rate),
so its shadow equals the device's loop and its parameter image matches.

``loop_on_emulator(source, fmax, ...)`` is a context manager: the emulator is
started, the link opened and armed without a ramp, the ``ClosedLoop`` yielded;
on exit the link is closed and the emulator stopped. A trial needs a fresh
device world, so each trial starts its own emulator (about a second).
"""

import tempfile
from contextlib import contextmanager
from pathlib import Path

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.loop_link import DEFAULT_PACKET, LoopLink

SILENCE = 10.0  # s: a lock-step emulator on a loaded machine may pause; its own clock does not run


@contextmanager
def loop_on_emulator(source, fmax, rate=5000.0, gesture="strokes", seed=0, late=1, packet=DEFAULT_PACKET):
    """A ``ClosedLoop`` at ``fmax`` N with ``source`` on the emulator's device loop (see the module's text)."""
    from studyapp.device.loop_bank import names_of
    from studyapp.model.loop import ClosedLoop, LoopConfig

    with tempfile.TemporaryDirectory(prefix="studyapp-device-loop-") as folder:
        link = Path(folder) / "device"
        emulator = EmulatorProcess(link, "--loop", "device", "--lockstep", "--rate", f"{rate:g}", "--seed",
                                   str(int(seed)), "--gesture", gesture)
        emulator.start()
        device = None
        try:
            device = LoopLink(link, rate, packet=packet, lead=packet + int(late), ramp_ms=0, silence=SILENCE)
            estimators = {name: {} for name in names_of(device.loop_info.kinds)}
            loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax,
                                         gesture=gesture, seed=seed, audio=False), device=device, judge=False)
            device.arm(0)
            yield loop
        finally:
            if device is not None:
                device.close()
            emulator.stop()


def factory(late, packet=DEFAULT_PACKET):
    """``make_loop`` for model/breakdown.py: each trial on a fresh emulator, the host ``late`` samples behind."""

    def make_loop(source, fmax, rate, gesture, seed):
        return loop_on_emulator(source, fmax, rate=rate, gesture=gesture, seed=seed, late=late, packet=packet)

    return make_loop
