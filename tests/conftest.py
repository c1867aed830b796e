"""Import studyapp before anything imports numba, so its cache directory is set (studyapp.numba_cache).

The dummy JACK server fixture (``jack_server``) serves the engine and the GUI tests alike.
"""

import studyapp  # noqa: F401
from tests.jack_server import jack_server  # noqa: F401


def pytest_collection_modifyitems(items):
    """The long cases first: slow, then those that run in real time (an engine on JACK, a GUI session).

    xdist hands each worker a share of the list in order and lets an idle one take from the others'
    tails; with the long ones last, one worker ran them alone at the end (the last 3 % of a clean
    run took 4 of its 12 minutes, 2026-11-25). The sort is stable: a module's tests keep their order.
    """
    def weight(item):
        if item.get_closest_marker("slow"):
            return 0
        if item.get_closest_marker("gui") or item.get_closest_marker("jack"):
            return 1
        return 2

    items.sort(key=weight)
