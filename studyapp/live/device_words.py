"""The device the loop runs on, in words for the console's Apparatus panel. No Qt.

From a link device's ``info`` (link_device.LinkDevice.info, sent by the
engine as ``DeviceInfo``): the handshake (name, serial number, protocol and
firmware versions, rate, channels with their SI units), the calibration's
source (the handshake's own gains, or a TOML file), the round trip measured
at open (PING probe: median and 99th percentile) and the link's latency (the
samples the host answers ahead, and the same in ms), or "loop on the device" for a
device that runs the loop itself (protocol 2: latency 0, the paper's loop). From a ``DeviceHealth``:
a step's frame counts, the problems first, the step named as the console counts it (``step_words``).
"""

UNITS = {"position": "m", "velocity": "m/s", "acceleration": "m/s²"}
SIMULATED = "simulated 1-DOF device (in the engine): link latency 0 samples, 0 ms"
PROBLEMS = ("corrupt", "lost", "missing", "late", "faults", "clamped")


def handshake(info):
    channels = ", ".join(f"{name} ({UNITS.get(name, '?')})" for name in info.get("channels", ()))
    return (f"{info['name']}, serial {info['serial']}; protocol v{info['protocol']}, firmware {info['firmware']}; "
            f"{info['rate']:g} Hz; channels {channels}")


def calibration(info):
    source = str(info.get("calibration", "?"))
    return "handshake (the device's own gains)" if source == "device" else f"TOML file {source}"


def runs_loop(info):
    """True for a device that runs the loop itself (protocol 2, loop_link.LoopLink.info)."""
    return info.get("loop") == "device"


def latency(info):
    trip = info.get("round_trip_ms") or {}
    measured = (f"round trip {trip['median']:.2f} ms median, {trip['p99']:.2f} ms p99"
                if "median" in trip and "p99" in trip else "round trip not measured")
    if runs_loop(info):
        return (f"loop on the device: force from the same sample's sensors (latency 0, the paper's loop); "
                f"telemetry in packets of {info.get('packet', 1)}, settings {1e3 * info['lead_samples'] / info['rate']:.1f}"
                f" ms ahead, keep-alive {info['keepalive_ms']} ms; {measured}")
    return (f"loop on the host: link latency {info['latency_samples']} samples = {info['latency_ms']:.2f} ms "
            f"(packets of {info.get('packet', 1)}); {measured}")


def late_risk(info):
    """A warning when the measured round trip's p99 exceeds the link latency (forces would come too late);
    never for a device loop, whose forces do not cross the link."""
    trip = info.get("round_trip_ms") or {}
    if not runs_loop(info) and "p99" in trip and trip["p99"] > info["latency_ms"]:
        return (f"the measured round trip (p99 {trip['p99']:.2f} ms) exceeds the link latency "
                f"({info['latency_ms']:.2f} ms): some forces will arrive late (counted, never applied)")
    return None


def health(where, counts):
    """A step's frame counts: ``step 3 of 12: 5000 frames, ...`` (``where``: ``step_words``)."""
    frames = counts.get("frames", 0)
    problems = ", ".join(f"{counts.get(key, 0)} {key}" for key in PROBLEMS)
    return f"{where}: {frames} frames, {counts.get('samples', 0)} samples; {problems}"


def step_words(tag, steps, total):
    """The engine's trial ``tag`` in the experimenter's words: the session's step it ran (``steps``: tag ->
    step index, ``total`` steps), else the tag itself. The engine tags a held page with its tag negated:
    the console said "trial -5" (issue 41, item 12)."""
    step = steps.get(abs(int(tag)))
    if step is not None:
        return f"step {step + 1} of {total}"
    if tag == 0:
        return "no step (the engine's start, or the preview)"
    return f"trial {tag}" if tag > 0 else f"a held page ({-tag})"
