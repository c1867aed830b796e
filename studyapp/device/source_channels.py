"""The device channels a velocity source reads, and the refusal of a device that lacks one.

The force (the paper's eq. 1 friction) is computed from one velocity, the source (model/sources.py). LVT, the
study's reference condition, is the linear velocity transducer's reading (paper Sec. 8.4): on a device on a link it
is the device's velocity channel. A device that sends no velocity channel (a position-only encoder) gets 0 m/s there
(handshake.Scales fills a missing channel with zeros, as a device loop does), so LVT's force would be 0 N all run,
with nothing said. An estimator reads its ``inputs`` (position; KALMAN, KALLEVACC, KALFOAWACC, COMP1 and COMP2
acceleration too); TRUE reads no channel (it is the simulation's own velocity, refused on a device elsewhere).

``check(sources, channels, link)`` refuses (one line: the source, the missing channel, what the device sends and
what is allowed) any source of a run or a protocol that reads a channel the device does not send.
"""

from studyapp.errors import ParameterError
from studyapp.model.sources import LVT_SENSOR, TRUE


def channels_read(source):
    """The device channels ``source`` reads (names as calibration_file.CHANNELS)."""
    if source == LVT_SENSOR:
        return ("velocity",)
    if source == TRUE:
        return ()
    from studyapp.estimators.registry import spec  # numba: only for an estimator's source

    return spec(source).inputs


def check(sources, channels, link):
    """``ParameterError`` if a source in ``sources`` reads a channel not in the device's ``channels``."""
    for source in sources:
        missing = [c for c in channels_read(source) if c not in channels]
        if missing:
            raise ParameterError(
                f"device at {link}: the source {source} reads the {missing[0]} channel, which the device does not "
                f"send (it sends {', '.join(channels)}): it would run on zeros (LVT: 0 N all run); allowed is a "
                f"source that reads only {' and '.join(channels)} (an estimator such as LOWPASS) or a device with a "
                f"{missing[0]} channel; refused")
