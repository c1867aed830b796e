"""Calibration: the simulated world's constants, each with its source or reason.

PLACEHOLDER VALUES FIRST-PASS; final values and the breakdown search follow.
"""

F0 = 147.0
DEVICE_MASS = 0.08
HAND_MASS = 0.02
HAND_STIFFNESS = 1000.0
HAND_DAMPING = 5.0
VELOCITY_SCALE = 2.5
STROKE_AMPLITUDE = 0.008
STROKE_SPEED = 0.02
STROKE_RAMP = 0.05
STROKE_DWELL = 0.1
VALIDATION_STROKES = dict(amplitude=0.007, speed=0.023, ramp=0.06, dwell=0.15)


def describe():
    """The constants as a dict (stored in recordings' metadata)."""
    return {k.lower(): v for k, v in globals().items() if k.isupper()}
