"""The parameter image of a device loop and its CRC (docs/device-protocol.md, "The parameter image").

A version 2 device that runs the loop says in INFO what its loop computes
with: the CRC-32 (zlib's) of the image

    rate_hz                                    u32
    the estimator kinds, in INFO's order       u8 each
    the estimators' parameter rows             f64 each: the bank's parameter array row by row, each row
                                               padded with zeros to the longest (estimators/estimator.py Bank)
    the string's parameters                    f64 each (model/bowed_string.py P_*)
    the motor limits' parameters               f64 each (model/device.py LP_*)
    velocity scale, peak |rho v|, breakaway    f64 (model/control.py C_SCALE, C_PEAK, C_BREAKAWAY)

all little-endian. The host builds the same image from its own loop at the
same rate and refuses a device whose CRC differs: its shadow of the loop
would not equal the device's. What CONTROL sets (source, bowing, gain,
force scale) and the loop's state are not in it.
"""

import struct
import zlib

import numpy as np

from studyapp.model.control import C_BREAKAWAY, C_PEAK, C_SCALE


def image(rate, arrays):
    """The image's bytes for a loop at ``rate`` Hz (an integer) on ``arrays`` (model/control.py Control.arrays)."""
    ctl, _state, lp, _ls, kinds, _est_s, est_p, sp = arrays[:8]
    f64 = np.dtype("<f8")
    return b"".join((
        struct.pack("<I", int(rate)),
        bytes(int(k) for k in kinds),
        np.ascontiguousarray(est_p, dtype=f64).tobytes(),
        np.ascontiguousarray(sp, dtype=f64).tobytes(),
        np.ascontiguousarray(lp, dtype=f64).tobytes(),
        struct.pack("<3d", ctl[C_SCALE], ctl[C_PEAK], ctl[C_BREAKAWAY]),
    ))


def image_crc(rate, arrays):
    """INFO's ``image``: zlib's CRC-32 of ``image(rate, arrays)``."""
    return zlib.crc32(image(rate, arrays))
