"""The simulated world: bowed-string waveguide, simulated 1-DOF device and sensors, virtual hand, closed loop.

    simulate.simulate(fmax, rate=5000.0, duration=7.0, source=LVT_SENSOR, ...) -> Recording
    data_set.PAPER_FMAX      the paper's 15 recording gains (Sec. 6.1), N
    loop.LoopConfig, loop.ClosedLoop   the closed haptic loop, run block by block
    limits                   the motors' limits, FMAX_LIMIT and the gesture names (no numba)
    fmax_knob                the F_max knob's law

The package imports none of its modules, so reading a constant (limits.py,
fmax_knob.py) does not compile the loop: import each from its module.
"""
