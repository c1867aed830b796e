"""The bow table: the bow-string junction's reflection coefficient rho(v_delta).

Smith's bowed string (paper ref. [5]) as in STK's ``BowTable``:

    rho(v) = clip( (|slope * (v + offset)| + 0.75)^-4 , 0.01, 0.98 )

with v = v_delta = v_bow - v_h the bow velocity minus the velocity the incoming
string waves would have at the bow, both in string units. rho = 0.98 is sticking,
small rho is slipping. ``slope`` plays the role of bow pressure (STK: 5 - 4 * pressure).

Friction force and its peak (paper eqs. 2 and 20). The junction adds
rho(v) * v to both outgoing waves; a force f on a string of wave impedance Z
launches f / (2 Z) each way, so the string-on-bow force is
F_b = -2 Z rho(v) v = -R_b(v) v with R_b = 2 Z rho(v) (eq. 2). With the gain
G (N per string unit) standing for 2 Z, F = -G rho(v) v and

    F_max = max_v |F| = G * max_v |rho(v) v|        (eq. 20).

The maximum of |rho(v) v|: where rho is clipped at 0.98 the product is
0.98 |v| and grows with |v|; beyond the clip it is |v| (slope |v + offset| + 0.75)^-4,
whose unclipped maximum would lie at slope |v| = 0.25 where the unclipped rho is 1,
i.e. still inside the clipped region. So the maximum sits exactly at the clip's
edge, |slope (v + offset)| = c with c = 0.98^(-1/4) - 0.75 = 0.255076:

    max |rho(v) v| = 0.98 * (c / slope + |offset|)

= 0.0833 for slope 3 and offset 0 (0.0843 with STK's offset 0.001, whose two
signs differ: 0.0823 and 0.0843). So G = F_max / max|rho v|. Our default offset is 0:
the handle bows both ways and F_max must hold in both directions.

The tail. STK's lower clip rho >= RHO_MIN = 0.01 (reached at slope |v| = 2.41,
|v| = 0.80 string units at slope 3) makes |rho v| = 0.01 |v| grow again
without limit: it passes the edge's maximum at |v| = 8.33 (at slope 3), which a
noisy or unstable velocity source reaches (BDIFF at 96 kHz drove 2x F_max,
LEVANT with C = 1e5 7.5x). ``friction`` therefore caps |rho v| at the maximum
above: the junction's wave u and the force -G u are one number, so the string
and the handle feel the same force, and |F| <= F_max holds by construction.
Below |v| = 8.33 nothing changes (the cap only flattens the clipped tail).
"""

import numpy as np
from numba import njit

RHO_MAX = 0.98
RHO_MIN = 0.01
EDGE = RHO_MAX ** -0.25 - 0.75  # |slope (v + offset)| at the clip's edge


@njit(cache=True, inline="always")
def rho(v, slope, offset):
    """The reflection coefficient for a velocity difference ``v`` (string units)."""
    t = abs(slope * (v + offset)) + 0.75
    t2 = t * t
    r = 1.0 / (t2 * t2)
    if r > RHO_MAX:
        return RHO_MAX
    if r < RHO_MIN:
        return RHO_MIN
    return r


@njit(cache=True, inline="always")
def friction(v, slope, offset, peak):
    """u = rho(v) v, with |u| capped at ``peak`` = ``peak_friction(slope, offset)`` (the tail; docstring)."""
    u = rho(v, slope, offset) * v
    if u > peak:
        return peak
    if u < -peak:
        return -peak
    return u


def peak_friction(slope, offset=0.0):
    """max over v of |rho(v) v| (closed form; see the module docstring)."""
    return RHO_MAX * (EDGE / slope + abs(offset))


def breakaway(slope, offset=0.0):
    """The largest |v_delta| at which the bow still sticks (rho at its clip 0.98)."""
    return EDGE / slope + abs(offset)


def table(v, slope=3.0, offset=0.0):
    """rho over an array (for plots and tests), STK's clipped table without the cap."""
    v = np.asarray(v, dtype=np.float64)
    return np.clip((np.abs(slope * (v + offset)) + 0.75) ** -4.0, RHO_MIN, RHO_MAX)


def friction_table(v, slope=3.0, offset=0.0):
    """u = rho(v) v over an array with the cap at peak_friction: what the string and the force use."""
    peak = peak_friction(slope, offset)
    return np.clip(table(v, slope, offset) * np.asarray(v, dtype=np.float64), -peak, peak)
