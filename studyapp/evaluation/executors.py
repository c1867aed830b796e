"""Where the parameter sets are evaluated: a ``concurrent.futures.Executor``.

- ``InlineExecutor``: in this process, one task at a time (``--workers 1``,
  tests, debugging).
- a ``ProcessPoolExecutor`` over all cores by default; each worker process
  loads the recordings and warms up the compiled estimators once.
- a dask.distributed ``Client``'s executor (``--scheduler ADDRESS``), to carry
  a large study past one machine; the workers must see the recording files at
  the same paths (a shared file system) and have studyapp installed.

Any other ``Executor`` works too: the optimiser only calls ``submit``, and asks
``parallelism`` how many tasks to split an iteration into.
"""

import os
from concurrent.futures import Executor, Future, ProcessPoolExecutor

from studyapp.errors import UserError


class InlineExecutor(Executor):
    """Runs each task at once, in the calling thread."""

    def submit(self, fn, /, *args, **kwargs):
        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:
            future.set_exception(exc)
        return future


class ClusterExecutor(Executor):
    """A dask.distributed ``Client``'s executor that also closes the client on shutdown."""

    def __init__(self, client):
        self.client = client
        self.executor = client.get_executor()
        self.workers = max(1, sum(client.nthreads().values()))  # the cluster's threads when it connected

    def submit(self, fn, /, *args, **kwargs):
        return self.executor.submit(fn, *args, **kwargs)

    def shutdown(self, wait=True, *, cancel_futures=False):
        try:
            self.executor.shutdown(wait=wait)
        finally:
            self.client.close()


def parallelism(executor):
    """How many tasks ``executor`` runs at once (1 for ``InlineExecutor`` and unknown executors)."""
    return int(getattr(executor, "workers", None) or getattr(executor, "_max_workers", None) or 1)


def cpu_count():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


PER_CORE = 4  # worker processes beyond this many per core only add memory (each loads numba and the recordings)


def check_workers(workers):
    """``--workers``: an integer from 1 to ``PER_CORE`` per core of this machine (``UserError`` otherwise)."""
    top = PER_CORE * cpu_count()
    if workers is not None and not 1 <= workers <= top:
        raise UserError(f"--workers {workers}: allowed is an integer from 1 to {top} "
                        f"({PER_CORE} per core of this machine)")


def make_executor(workers=None, scheduler=None, initializer=None, initargs=()):
    """The executor for ``--workers`` / ``--scheduler`` (``initializer`` runs once per local worker)."""
    if scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise UserError(
                f"--scheduler {scheduler}: needs dask.distributed, which is not installed "
                "(pip install 'dask[distributed]')") from None
        try:
            client = Client(scheduler)
        except (OSError, TimeoutError, ValueError) as exc:
            raise UserError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
        return ClusterExecutor(client)
    check_workers(workers)
    workers = cpu_count() if workers is None else int(workers)
    if workers == 1:
        if initializer is not None:
            initializer(*initargs)
        return InlineExecutor()
    return ProcessPoolExecutor(max_workers=workers, initializer=initializer, initargs=initargs)
