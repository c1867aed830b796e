"""``--device simulated|PATH_OR_URL`` of ``studyapp gui`` and ``studyapp run``, and the rig check ``run`` prints.

``simulated`` is the engine's simulated device; a path or URL is a device
speaking docs/device-protocol.md (a serial port, ``studyapp device-emulator``'s
pty, ``socket://HOST:PORT``), probed before any window opens (link_probe.py:
one line and exit code 2 for a link that is not such a device). Without the
option the console uses the device remembered on this machine (its Apparatus
panel's choice).

``rig_check_line(protocol, device, say)``: before a session with an
adjustment task on a device on a link, the model's prediction at the link's
latency (live/rig_check.py, seconds of CPU per condition) and, when LVT falls
below 1.5x the best estimator, the warning line (the console asks the same at
Start). The simulated device is the paper's own loop: nothing to check; so
is a device that runs the loop itself (its INFO says so: the line says that).
"""

from studyapp.errors import ParameterError

SIMULATED = "simulated"


HEADLESS_WHY = ("a headless session steps the simulated device as fast as it can, and a device on a link runs "
                "on its own clock")


def add_device_option(parser, headless=False):
    """``--device``; ``headless``: the command also has ``--headless``, with which a link is refused (say why)."""
    words = f" (the console's; not with --headless: {HEADLESS_WHY})" if headless else ""
    parser.add_argument("--device", metavar="simulated|PATH_OR_URL", default=None,
                        help="the device: simulated, or a link to a device speaking docs/device-protocol.md "
                             f"(serial port, pty, socket://HOST:PORT); default: the one remembered on this "
                             f"machine{words}")
    parser.add_argument("--device-latency", type=int, default=None, metavar="SAMPLES",
                        help="samples the host answers ahead of a link device's sensor sample, as for live "
                             "(default 5); the rig check predicts at it")
    parser.add_argument("--device-silence", type=float, default=None, metavar="SECONDS",
                        help="a link device silent for longer is a device fault, as for live (default 0.02)")


def link_options(args, link):
    """``EngineConfig``'s ``device_*`` fields the console's engines take from ``--device-latency`` and
    ``--device-silence`` (checked: ``ParameterError``, one line); refused without a link device."""
    from studyapp.device import handshake

    given = {"device_latency": getattr(args, "device_latency", None),
             "device_silence": getattr(args, "device_silence", None)}
    given = {key: value for key, value in given.items() if value is not None}
    if given and link is None:
        raise ParameterError("--device-latency and --device-silence need --device PATH_OR_URL (a link device)")
    if "device_latency" in given:
        handshake.check_latency(given["device_latency"])
    if "device_silence" in given:
        given["device_silence"] = handshake.check_silence(given["device_silence"])
    return given


def check_device(device, rate, protocol=None):
    """None for the simulated device, else the link (probed: ``ParameterError``, one line, if it is no device)."""
    return probe_device(device, rate, protocol)[0]


def protocol_sources(protocol):
    """Every condition (velocity source) of the protocol's tasks, in the order they first appear."""
    names = []
    for task in protocol.tasks:
        names += [n for n in getattr(protocol.task(task), "conditions", ()) if n not in names]
    return names


def probe_device(device, rate, protocol=None):
    """(link, who runs the loop: "host" or "device") of ``--device``; (None, None) for the simulated device.
    A device that lacks a channel one of ``protocol``'s conditions reads is refused (source_channels.py)."""
    if device is None or device == SIMULATED:
        return None, None
    from studyapp.device import source_channels
    from studyapp.device.link_open import is_link
    from studyapp.device.link_probe import probe

    if not is_link(device):
        raise ParameterError(f"--device {device}: allowed is simulated, a serial port, a pty or a pyserial URL")
    found = probe(device, rate)
    if protocol is not None:
        source_channels.check(protocol_sources(protocol), found["channels"], device)
    return device, found["loop"]


def rig_check_line(protocol, device, say, loop=None, latency=None):
    """Predict the protocol's adjustment conditions on the rig (``say`` the progress); returns (request, prediction,
    warning line or None), or None when there is nothing to check. ``loop``: "device" for a device that runs the
    loop itself (``probe_device``)."""
    from studyapp.engine.config import EngineConfig
    from studyapp.live import rig_check

    config = EngineConfig(rate=protocol.rate, device=device)
    if latency is not None:
        config.device_latency = int(latency)
    rig = rig_check.rig_of(config, loop)
    req = rig_check.request(protocol, rig)
    if req is None:
        return None
    if not rig_check.needs_check(rig):
        if rig.kind == rig_check.DEVICE_LOOP:
            say(f"rig check: {rig.words}; LVT's margin is the model's own, nothing to predict")
        return None
    cache = rig_check.PredictionCache(rig_check.cache_path())
    prediction = cache.get(req)
    if prediction is None:
        say(f"rig check: predicting the bowing breakdown of {len(req.conditions)} conditions at {rig.latency_words} "
            "link latency (the model, 5 seeds)…")
        prediction = rig_check.predict(req)
        cache.put(req, prediction)
    else:
        say(f"rig check: the prediction at {rig.latency_words} link latency kept from an earlier launch "
            f"({rig_check.cache_path()})")
    verdict = rig_check.verdict(prediction, rig)
    say(f"rig check: {verdict.text}")
    if verdict.warning is not None:
        say(verdict.warning)
    return req, prediction, verdict.warning
