"""The sensors a device streams, in SI, checked before the loop sees them: finite and physically possible.

A sensor value that is NaN or infinite, or beyond what a haptic handle can
do, is a device fault the host detects (it never reaches the loop, whose
force would follow it). The bounds are far above any rig's (the TGR's
travel is +-11 mm, its strokes 0.15 m/s; model/limits.py) and far below a
broken encoder's or a garbled firmware's values (1e300): a hand-held handle
does not leave 1 m, move at 100 m/s or accelerate at 10^5 m/s^2 (10,000 g).
"""

import math

BOUNDS = {"position": 1.0, "acceleration": 1e5, "velocity": 100.0}  # |SI value| allowed: m, m/s^2, m/s


def check(sample, x, a, v):
    """None if every value is finite and within ``BOUNDS``; else one line naming the first that is not
    (``sample``: the device sample of the rows' first)."""
    for name, values in (("position", x), ("acceleration", a), ("velocity", v)):
        bound = BOUNDS[name]
        for i, value in enumerate(values):
            if not (math.isfinite(value) and -bound <= value <= bound):
                return (f"the device's {name} at its sample {(sample + i) & 0xFFFFFFFF} is {value!r}: allowed is a "
                        f"finite number within +-{bound:g} (SI)")
    return None
