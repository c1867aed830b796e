"""Import studyapp before anything imports numba, so its cache directory is set (studyapp.numba_cache); the rig
check's kept predictions go to a folder of this run.

The dummy JACK server fixture (``jack_server``) serves the engine and the GUI tests alike. The long files
are collected first (``pytest_collection_modifyitems``), so the parallel run does not end on one of them.
"""

import os
import tempfile

import studyapp  # noqa: F401
from tests.hang_guard import pytest_runtest_protocol, pytest_terminal_summary  # noqa: F401
from tests.jack_server import jack_server  # noqa: F401

# the rig check's predictions kept between launches (live/rig_check.py): the suite's own, in a folder of this run,
# never the user's (a test's stand-in prediction must not be shown as a rig's), inherited by the commands it runs
os.environ["STUDYAPP_RIG_PREDICTIONS"] = os.path.join(tempfile.mkdtemp(prefix="studyapp-tests-"),
                                                      "rig_predictions.json")


def pytest_collection_modifyitems(config, items):
    """The long files first: those with a ``slow`` test, and the GUI folder (sessions in real time).

    ``make test`` spreads the suite over its workers with xdist's worksteal: each worker takes half of the
    collection in order, and one that runs out takes half of the other's tests not yet started, from the end.
    A long test late in a worker's half ran on while the other worker, done, had nothing to take: the run's
    tail. Started first, the long ones end while short ones remain to share. Whole files move (and the GUI
    folder as one block, in its order), so a module's or the folder's shared fixture is set up once per worker.
    """
    def long(item):
        return item.get_closest_marker("slow") is not None or item.nodeid.startswith("tests/gui/")

    front = {item.nodeid.split("::")[0] for item in items if long(item)}
    items.sort(key=lambda item: item.nodeid.split("::")[0] not in front)
