"""The adjustment knob: a 7-bit knob position mapped logarithmically to F_max.

The paper's participants raised F_max "logarithmically by turning to the
right", from F_max = 0 (Sec. 8.2). A pure logarithm cannot reach 0, so the map
is an exponential shifted to start there:

    F_max(k) = ceiling * (10^(d u) - 1) / (10^d - 1),   u = k / 127,  k = 0..127

with ``d`` the number of decades. F_max(0) = 0 and F_max(127) = ceiling; above
about a tenth of the ceiling one knob step multiplies F_max by nearly
10^(d/127) (5.6 % for d = 3), so relative resolution is the same at every
level, as with a logarithmic scale; near 0 the steps are ceiling/(10^d - 1)
times d ln(10)/127 wide (2.2e-3 N for a 40 N ceiling and d = 3). Its inverse is

    k(F) = 127 / d * log10(1 + F (10^d - 1) / ceiling).
"""

import math

KNOB_MAX = 127


def fmax_from_knob(k, ceiling, decades):
    """F_max (N) at knob position ``k`` (0..127)."""
    u = k / KNOB_MAX
    return ceiling * math.expm1(decades * u * math.log(10.0)) / math.expm1(decades * math.log(10.0))


def knob_from_fmax(fmax, ceiling, decades):
    """The (real-valued) knob position whose F_max is ``fmax``; round it for a knob."""
    return KNOB_MAX / decades * math.log10(1.0 + fmax * math.expm1(decades * math.log(10.0)) / ceiling)
