"""The simulated world: bowed-string waveguide, simulated 1-DOF device and sensors, virtual hand, closed loop.

    simulate(fmax, rate=5000.0, duration=7.0, source=LVT_SENSOR, ...) -> Recording
    PAPER_FMAX          the paper's 15 recording gains (Sec. 6.1), N
    LoopConfig, ClosedLoop   the closed haptic loop, run block by block
"""

from studyapp.model.data_set import PAPER_FMAX
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.simulate import simulate

__all__ = ["PAPER_FMAX", "ClosedLoop", "LoopConfig", "simulate"]
