"""``studyapp compile``: compile every numba kernel once, so that no session, engine or test waits for it.

The kernels are compiled on their first call and kept in numba's cache
(``studyapp/numba_cache.py``: a folder per version of the compiled source).
On a new machine, or after an update, the first call of each pays for its
compile: 25 s or more for the closed loop alone, which the real-time engine
would spend before its first block, and which every process of a parallel
test run would spend at once. This command makes those first calls on a few
samples, in the app's own paths: the closed loop with an estimator in it and
on a real device's per-sample interface, the optimiser's side-by-side
kernels, the estimator bank and benchmark, the metric (one-off and the
optimiser's memorised reference), the stability monitor on a recording,
FOAW's window sizes, the audio resampler and the scope's envelope; and it
builds the device emulator's C core (studyapp/device/c_core.py) and the
estimators and the loop in C (studyapp/device/c_estimators.py, c_loop.py).
Every later process loads the compiled code from the cache; a warm cache makes
this take a few seconds. ``make run`` and ``make test`` call it.

The parts run in two processes at once (``--jobs``), one per core of a
two-core machine; the closed loop, the longest, starts first. (Splitting it
further costs more than it saves: two processes would each compile the
callees the parts share.)
"""

import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed

JOBS_MAX = 8


def register(sub):
    parser = sub.add_parser("compile", help="compile the numba kernels once (a new machine, after an update)")
    parser.add_argument("--jobs", type=int, default=2, help=f"processes that compile at once, 1..{JOBS_MAX} "
                                                            "(default 2)")
    parser.set_defaults(func=run)


def closed_loop():
    """The loop the engine and ``simulate`` run, with the paper's sensor and with an estimator in it, and the
    same loop on a real device's per-sample interface (model/device.py ``exchange``). One part: they share
    most of their compiled callees, which two processes would each compile."""
    from studyapp.model.device import DeviceLimits, HapticDevice
    from studyapp.model.loop import ClosedLoop, LoopConfig
    from studyapp.model.simulate import simulate

    class StillHandle(HapticDevice):
        """A driver whose handle stays at rest."""

        rate, limits = 5000.0, DeviceLimits()

        def read_sensors(self):
            return 0.0, 0.0, 0.0

        def write_force(self, force):
            pass

    simulate(1.0, duration=0.05)
    simulate(1.0, duration=0.05, source="KALMAN")
    ClosedLoop(LoopConfig(rate=StillHandle.rate, fmax=1.0, source="LVT"), device=StillHandle()).run(100)


def shadow_of_a_device_loop():
    """The host's shadow of a device that runs the loop (device/shadow.py; also ``bench loop``'s numba loop), on
    a few rows at rest. A part of its own: its estimator dispatch is as long to compile as the closed loop."""
    import numpy as np

    from studyapp.device import shadow
    from studyapp.model.control import OUTPUTS
    from studyapp.model.loop import ClosedLoop, LoopConfig

    loop = ClosedLoop(LoopConfig(rate=5000.0, fmax=1.0, source="LVT", audio=False), judge=False)

    rows = np.zeros((4, shadow.ROW_WIDTH))
    shadow.run_rows(loop.control.arrays, 0, rows, 0.0, shadow.CHECK, np.zeros((len(OUTPUTS), 4)),
                    np.zeros((len(loop.names), 4)), np.zeros(2))


def estimator_bank():
    """Every estimator in the bank the engine and ``estimate`` run, and the estimator benchmark."""
    import numpy as np

    from studyapp import estimators
    from studyapp.estimators.benchmark import cost
    from studyapp.estimators.spec import RATE_MAX
    from studyapp.evaluation.dataset import warm_up

    names = estimators.names()
    warm_up(names)
    cost(names[0], RATE_MAX, n=1000, repeats=1)
    x = np.zeros(64)
    estimators.Bank(RATE_MAX, names).process(x, x, x)


def optimiser_kernels():
    """The optimiser's side-by-side kernels, one per estimator (evaluation/kernels.py)."""
    from studyapp import estimators
    from studyapp.evaluation.dataset import warm_up

    warm_up(estimators.names(), fast=True)


def signal_paths():
    """The metric (eqs. 22-24, one-off and the optimiser's memorised reference), the stability monitor on a
    recording, FOAW's window sizes (Fig. 6), the engine's audio resampler and the scope's envelope."""
    import numpy as np

    from studyapp.engine.resampler import Resampler
    from studyapp.estimators.foaw import window_sizes
    from studyapp.evaluation import delay_and_error
    from studyapp.evaluation.metric import Reference
    from studyapp.live.scope_buffer import envelope
    from studyapp.model.stability import StabilityMonitor

    t = np.arange(400) / 5000.0
    v = np.sin(2 * np.pi * 50 * t)
    delay_and_error(v, np.roll(v, 2), 20)
    Reference(v, 20).measure(np.roll(v, 2))
    StabilityMonitor(5000.0, 440.0).measure(v)
    window_sizes(np.cumsum(v) / 5000.0, 16, 0.001)
    resampler = Resampler(5000.0, 48000.0)
    resampler.process(v)
    resampler.flush()
    envelope(np.zeros((2, 64)), 4)


def device_core():
    """The device protocol's C core (firmware/studyapp_device.c), which the device emulator runs when it builds
    (without a C compiler the emulator runs the Python core and says so), the estimators in C
    (firmware/studyapp_estimators.h, studyapp/device/c_estimators.py) and the loop in C with them
    (firmware/studyapp_loop.h, studyapp/device/c_loop.py), and the device core with that loop, which
    ``device-emulator --loop device`` runs (firmware/studyapp_device_loop.h, studyapp/device/c_loop_core.py)."""
    from studyapp.device import c_core, c_estimators, c_loop, c_loop_core
    for build in (c_core.build, c_estimators.build, c_loop.build, c_loop_core.build):
        try:
            build()
        except c_core.BuildError:
            pass


# longest first (measured 2026-11-28, a clean cache: 114, 84, 43, 20, 5 and 2 s), so two processes end together
PARTS = {"closed loop": closed_loop, "device loop's shadow": shadow_of_a_device_loop,
         "estimator bank": estimator_bank, "optimiser kernels": optimiser_kernels, "signal paths": signal_paths,
         "device C core": device_core}


def _timed(name):
    start = time.monotonic()
    PARTS[name]()
    return time.monotonic() - start


def run(args):
    from studyapp.errors import ParameterError

    if not 1 <= args.jobs <= JOBS_MAX:
        raise ParameterError(f"--jobs {args.jobs}: allowed is an integer from 1 to {JOBS_MAX}")
    start = time.monotonic()
    print(f"compile: {len(PARTS)} parts into {os.environ.get('NUMBA_CACHE_DIR')}", file=sys.stderr, flush=True)
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        parts = {pool.submit(_timed, name): name for name in PARTS}
        for done, part in enumerate(as_completed(parts), start=1):
            print(f"compile: {parts[part]} {part.result():.1f} s ({done} of {len(PARTS)})", file=sys.stderr,
                  flush=True)
    print(f"compile: done in {time.monotonic() - start:.1f} s", file=sys.stderr)
    return 0
