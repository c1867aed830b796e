"""The parameter image (loop_image.py, docs/device-protocol.md "The parameter image"): its bytes rebuilt by
hand from the parts the spec lists, and its CRC moved by a one-rounding change of any parameter, and by nothing
CONTROL sets."""

import struct
import zlib

import numpy as np
import pytest

from studyapp.device.loop_bank import device_loop
from studyapp.device.loop_image import image, image_crc
from studyapp.estimators import Bank
from studyapp.model import bow_table, calibration
from studyapp.model.bowed_string import StringDesign
from studyapp.model.control import C_BOWING, C_BREAKAWAY, C_FORCE_SCALE, C_GAIN, C_PEAK, C_SCALE, C_SOURCE
from studyapp.model.device import DeviceLimits


@pytest.fixture(scope="module")
def loop():
    return device_loop(5000, accelerometer=True)


def test_image_is_the_listed_parts(loop):
    names = loop.names
    bank = Bank(5000.0, {n: {} for n in names})
    string = StringDesign(5000.0, calibration.F0)
    expected = (struct.pack("<I", 5000) + bytes(int(k) for k in bank.kinds)
                + struct.pack(f"<{bank.params.size}d", *bank.params.ravel())
                + struct.pack("<8d", *string.params()) + struct.pack("<3d", *DeviceLimits().params(5000.0))
                + struct.pack("<3d", calibration.VELOCITY_SCALE, bow_table.peak_friction(string.slope, string.offset),
                              bow_table.breakaway(string.slope, string.offset)))
    assert image(5000, loop.control.arrays) == expected
    assert image_crc(5000, loop.control.arrays) == zlib.crc32(expected)


def test_every_parameter_moves_the_crc(loop):
    arrays = tuple(np.copy(a) for a in loop.control.arrays)
    ctl, _, lp, _, kinds, _, est_p, sp = arrays[:8]
    base = image_crc(5000, arrays)
    assert image_crc(5001, arrays) != base
    moved = 0
    for a, index in ([(est_p, i) for i in np.ndindex(est_p.shape)] + [(sp, (i,)) for i in range(sp.size)]
                     + [(lp, (i,)) for i in range(lp.size)] + [(ctl, (i,)) for i in (C_SCALE, C_PEAK, C_BREAKAWAY)]):
        old = a[index]
        a[index] = np.nextafter(old, np.inf)
        assert image_crc(5000, arrays) != base, (index, old)
        a[index] = old
        moved += 1
    for i in range(kinds.size):
        kinds[i] += 1
        assert image_crc(5000, arrays) != base
        kinds[i] -= 1
    assert image_crc(5000, arrays) == base and moved > 100


def test_control_settings_and_state_leave_it(loop):
    arrays = tuple(np.copy(a) for a in loop.control.arrays)
    base = image_crc(5000, arrays)
    ctl, state, _, ls, _, est_s = arrays[:6]
    ctl[C_GAIN], ctl[C_BOWING], ctl[C_SOURCE], ctl[C_FORCE_SCALE] = 3.0, 0.0, 2.0, 0.5
    state[:] = 1.0
    ls[:] = 2.0
    est_s[:] = 4.0
    for line in arrays[8:11]:
        line[:] = 5.0
    assert image_crc(5000, arrays) == base


def test_other_rates_and_banks_differ():
    crcs = {image_crc(rate, device_loop(rate, acc).control.arrays) for rate in (5000, 48000) for acc in (False, True)}
    assert len(crcs) == 4
