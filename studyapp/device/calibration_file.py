"""A lab's calibration of its devices: a TOML file keyed by serial number.

A device reports a gain and an offset per channel in its INFO frame
(docs/device-protocol.md), so that SI = gain * raw + offset. A lab that
calibrates its rig (an LVDT against a gauge block, an accelerometer on a
shaker) writes what it measured here; an entry overrides the device's own for
that serial number and channel::

    ["TGR-0001"]                                 # the serial number, as INFO reports it
    position = { gain = 2.5e-7, offset = -0.011 }    # m per count, m
    velocity = { gain = 1.0e-5, offset = 0.0 }       # (m/s) per count, m/s
    acceleration = { gain = 4.9e-3, offset = 0.0 }   # (m/s^2) per count, m/s^2

Channels not named keep the device's calibration. Each channel's table needs
both gain and offset (a missing one is named). Every value is checked as
INFO's are (messages.scale_problem): a gain non-zero, both finite and within
+-1000 SI units (per count), no other key; a bad file is one line naming the
file, the field and what is allowed. A file with no entry for the device's
serial is refused, naming both serials: a file made for another rig is never
silently ignored.
"""

import tomllib

from studyapp.device import messages
from studyapp.errors import ParameterError

CHANNELS = ("position", "acceleration", "velocity")  # INFO's channel kinds 0, 1, 2
FIELDS = ("gain", "offset")


def _number(path, where, field, value):
    problem = messages.scale_problem(field, value)
    if problem:
        raise ParameterError(f"{path}: {where}.{problem}")
    return float(value)


def load(path):
    """``{serial: {channel: (gain, offset)}}`` from the TOML file ``path``; ``ParameterError`` if it is bad."""
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except FileNotFoundError:
        raise ParameterError(f"--calibration {path}: no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ParameterError(f"--calibration {path}: cannot be read ({exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None
    table = {}
    for serial, channels in data.items():
        if not isinstance(channels, dict):
            raise ParameterError(f"{path}: [{serial!r}] must be a table of channels ({', '.join(CHANNELS)})")
        entry = {}
        for channel, values in channels.items():
            where = f"[{serial!r}].{channel}"
            if channel not in CHANNELS:
                raise ParameterError(f"{path}: {where}: unknown channel; allowed are {', '.join(CHANNELS)}")
            if not isinstance(values, dict):
                raise ParameterError(f"{path}: {where}: allowed is a table {{ gain = G, offset = O }}")
            missing = [key for key in FIELDS if key not in values]
            unknown = sorted(set(values) - set(FIELDS))
            if missing or unknown:
                what = f"no {' and no '.join(missing)}" if missing else f"unknown key {unknown[0]!r}"
                raise ParameterError(f"{path}: {where}: {what}; allowed is a table {{ gain = G, offset = O }}, "
                                     "both required")
            entry[channel] = (_number(path, where, "gain", values["gain"]),
                              _number(path, where, "offset", values["offset"]))
        table[serial] = entry
    return table


def apply(device_channels, serial, path):
    """The channels' (gain, offset) with the file's entry for ``serial`` in place, and where they came from.

    ``device_channels``: ``{channel: (gain, offset)}`` from INFO. Returns ``(channels, source)``,
    ``source`` being ``"device"`` or ``"PATH [SERIAL]"``.
    """
    channels = dict(device_channels)
    if path is None:
        return channels, "device"
    table = load(path)
    entry = table.get(serial)
    if entry is None:
        raise ParameterError(f"--calibration {path}: no entry for the device's serial {serial!r}; the file has "
                             f"{', '.join(repr(k) for k in table) or 'none'} (a file made for another device "
                             "is refused, not ignored)")
    for channel, pair in entry.items():
        if channel not in channels:
            raise ParameterError(f"{path}: [{serial!r}].{channel}: the device has no {channel} channel; "
                                 f"it has {', '.join(channels) or 'none'}")
        channels[channel] = pair
    return channels, f"{path} [{serial}]"
