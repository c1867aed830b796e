"""The driver for a device on a link, picked from its INFO: the host's loop or the device's own.

A version 1 device, or a version 2 one whose INFO says the host runs the loop,
gets ``LinkDevice`` (link_device.py: the host answers each sensor sample with a
force ``latency`` samples later). A version 2 device that runs the loop itself
(INFO.loop = 1) gets ``LoopLink`` (loop_link.py: telemetry and a shadow; the
force comes from the same sample's sensors on the device, the paper's loop).
No option chooses between them: the device says which it is (link_probe.py's
short handshake, then the driver's own).

``options`` are ``EngineConfig.link_options()``: ``latency`` and ``packet`` are
the host loop's (a device loop streams ``loop_link.DEFAULT_PACKET`` rows per
frame and tags its settings ``loop_link.LEAD_MS`` ahead); ``calibration``,
``ramp_ms`` and ``silence`` hold for both.
"""

from studyapp.device.link_probe import probe


def open_link_device(spec, rate, options):
    """The opened driver for the device on ``spec``; ``ParameterError`` (one line) if it is none that fits."""
    if probe(spec, rate, calibration=options.get("calibration"))["loop"] == "device":
        from studyapp.device.loop_link import LoopLink

        shared = {key: options[key] for key in ("calibration", "ramp_ms", "silence") if key in options}
        return LoopLink(spec, rate, **shared)
    from studyapp.device.link_device import LinkDevice

    return LinkDevice(spec, rate, **options)
