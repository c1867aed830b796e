"""Import studyapp before anything imports numba, so its cache directory is set (studyapp.numba_cache).

The dummy JACK server fixture (``jack_server``) serves the engine and the GUI tests alike.
"""

import studyapp  # noqa: F401
from tests.jack_server import jack_server  # noqa: F401
