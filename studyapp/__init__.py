"""studyapp: velocity estimation studies for audio-haptic stick-slip simulation.

After Sinclair, Wanderley and Hayward, "Velocity Estimation Algorithms for
Audio-Haptic Simulations Involving Stick-Slip", IEEE Trans. Haptics 7(4), 2014.
"""

from studyapp import numba_cache

__version__ = "0.1.0"

numba_cache.configure()
