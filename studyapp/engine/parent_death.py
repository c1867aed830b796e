"""The engine's child processes die with their parent, from their first instant (issue 41, item 16).

The worker and the force guard are spawned: a fresh interpreter that unpickles
its arguments before it runs a line of the app. The engine's configuration
imports the whole simulation (numba: 2.4 s on an idle machine), and the worker
then opens its devices, loads compiled code and primes its sink for a few
seconds more, all before its loop watches the parent. A SIGKILL of the parent
in that time left the worker (and the resource tracker, which waits for every
holder of its pipe) alive under PID 1, holding the shared memory, for good.

So a child is spawned through ``run``, a module that imports nothing heavy.
Its arguments travel pickled as bytes (``spawn_args``), unpickled only after
``run`` has asked the kernel to SIGKILL the process when its parent dies
(Linux ``prctl(PR_SET_PDEATHSIG)``, through ctypes) and checked that the parent
is still the one that spawned it (a parent that died before the request was
made is never signalled: ``os.getppid()`` has changed, and the child leaves at
once). Where there is no prctl (not Linux), a thread watches the parent's
sentinel (the pipe the parent holds; it reads end-of-file when the parent
dies) from the same instant and ends the process.

The kernel's signal comes when the *thread* that spawned the child ends, not
the process: a console starts its engine on a thread of its own that ends
once the engine runs. So the request holds only through start-up: once a
child's own loop watches its parent (the worker every 50 ms, the guard every
poll), it hands over (``watched``) and stops cleanly, switching its force off
first, when the parent goes.
"""

import ctypes
import importlib
import multiprocessing
import os
import pickle
import signal
import threading

PR_SET_PDEATHSIG = 1


def _pdeathsig(sig):
    """Ask the kernel for ``sig`` when the parent (thread) dies; False where prctl is not to be had."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_sentinel():
    """Without prctl: a thread that ends the process when the parent's sentinel reads end-of-file."""
    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch():
        parent.join()  # waits on the sentinel: returns when the parent has gone
        os.kill(os.getpid(), signal.SIGKILL)

    threading.Thread(target=watch, name="studyapp-parent-watch", daemon=True).start()


def follow_parent(parent_pid):
    """Die with the parent ``parent_pid`` from now on; leave at once if it is gone already."""
    if not _pdeathsig(signal.SIGKILL):
        _watch_sentinel()
    if os.getppid() != parent_pid:  # it died before the request: no signal will come
        os._exit(1)


def watched():
    """The child's own loop watches its parent from now on: the kernel's signal is no longer wanted."""
    _pdeathsig(0)


def spawn_args(target, *args):
    """``ctx.Process`` arguments running ``target(*args, **kwargs)`` through ``run`` (module docstring):
    ``(run, (parent pid, "module:function", pickled args))``. Keyword arguments that pickle only while
    spawning (a ``multiprocessing.Queue``) are passed as the process's ``kwargs``, as they are."""
    return run, (os.getpid(), f"{target.__module__}:{target.__name__}", pickle.dumps(args))


def run(parent_pid, target, packed, **kwargs):
    """The spawned child's entry: die with the parent first, then import and call ``target``."""
    follow_parent(parent_pid)
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)(*pickle.loads(packed), **kwargs)
