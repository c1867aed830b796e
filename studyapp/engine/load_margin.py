"""The watchdog's heartbeat bound on a busy machine: more margin when the machine is loaded, and a warning.

The force guard (guard.py) calls the worker hung when its heartbeat, written
once a block (2 ms), is older than ``hang_timeout`` (80 ms). On a machine
whose runnable processes outnumber its cores, the worker and the guard wait
for a core: a heartbeat then comes late without anything being wrong, and the
guard cut the force of a healthy engine (issue 31 item 9: five trips in one
session at a load of 7-12 on 2 cores, "no heartbeat for 81 ms, 80 ms
allowed"). The bound therefore follows the machine's load when the engine
starts:

    L = 1-minute load average / cores            (os.getloadavg, os.cpu_count)
    hang_timeout = base                           for L <= 1 (the default 80 ms)
    hang_timeout = min(base * L, MAX_BOUND)       above (at most 250 ms)

A real stall (a worker stopped, hung or dead) never writes its heartbeat
again, so any finite bound still finds it: the margin only delays the cut,
by at most MAX_BOUND - base = 170 ms. With L above ``BUSY`` = 1 the console
and ``run`` warn before the session starts (``busy_warning``): close other
programs, or expect a later force cut and more audio underruns.

The figures (``studyapp bench heartbeat``, docs/engine.md "Under load") come
from the machine this was measured on; a machine slower or busier needs a
look at its own.
"""

import os

BUSY = 1.0  # load per core above which the machine is busy
MAX_BOUND = 0.25  # s: the largest bound the load may give


def load_per_core():
    """The 1-minute load average per core (0 where the OS gives none)."""
    try:
        return os.getloadavg()[0] / (os.cpu_count() or 1)
    except OSError:
        return 0.0


def hang_timeout_for(load, base):
    """The heartbeat bound for ``load`` per core (module docstring); never below ``base``."""
    if load <= BUSY:
        return base
    return max(base, min(base * load, MAX_BOUND))


def busy_warning(load, base):
    """A warning for a session about to start at ``load`` per core (None when the machine is not busy)."""
    if load <= BUSY:
        return None
    bound = hang_timeout_for(load, base)
    return (f"the machine is busy (load {load * (os.cpu_count() or 1):.1f} on {os.cpu_count() or 1} cores): "
            f"the watchdog allows {1e3 * bound:.0f} ms without a heartbeat instead of {1e3 * base:.0f} ms, "
            "audio may underrun; close other programs before a session")
