"""``studyapp live``: the haptic loop in real time, headless, with a scripted gesture.

Prints the engine's status once a second on stderr; with ``--json`` prints one
JSON object on stdout at exit:
``{"rate", "achieved_rate", "deadline_misses", "audio_underruns", "faults", "midi_messages",
"events_dropped", ..., "device"}``; ``device`` is null on the simulated device, else the link device's
``info`` (docs/engine.md) with its ``health`` and ``fault``; ``events_dropped`` counts the worker's events (MIDI control events, notices)
that its event ring overwrote before this process read them.
Stops after ``--seconds`` or on Ctrl-C / SIGTERM, always cleanly (no orphan
process, no shared memory left behind). With ``--protocol`` the protocol's
F_max ceiling is the worker's hard clamp (experiment/protocol.py); without it,
the motors' sustained limit. With ``--device PATH_OR_URL`` the loop runs on
a real device (or ``studyapp device-emulator``) over its link, paced by the
device; a link that is not a device, or a device that does not fit, is refused
before the worker starts. Every setting is checked before the worker starts:
a bad one is one line, exit 2.
"""

from studyapp.cli import number_options


def register(sub):
    p = sub.add_parser("live", help="run the haptic loop in real time (audio out, MIDI knobs in)")
    p.add_argument("--rate", type=float, default=5000.0, help="haptic rate in Hz (default 5000)")
    p.add_argument("--source", default=None, help="velocity source: an estimator, LVT or TRUE (default LVT)")
    p.add_argument("--fmax", type=float, default=1.0, help="F_max in N (default 1), at most the ceiling")
    p.add_argument("--protocol", metavar="FILE",
                   help="a study protocol whose F_max ceiling clamps the force (default: the motors' 60 N)")
    p.add_argument("--estimators", default=None,
                   help="active estimators: comma-separated names or 'all' (default: just the source)")
    p.add_argument("--audio", default="device",
                   help="device | device:NAME | wav:FILE | null (default device; null if none is usable)")
    p.add_argument("--midi", default="first", help="PORT (name or part of it) | first | virtual | none (default first)")
    p.add_argument("--seconds", type=float, default=None, help="stop after this long (default: run until Ctrl-C)")
    p.add_argument("--gesture", default="strokes", help="scripted gesture (default strokes)")
    p.add_argument("--block", type=int, default=None, help="samples per block (default: 2 ms worth)")
    p.add_argument("--seed", type=number_options.seed, default=0, help="noise seed (default 0)")
    p.add_argument("--device", metavar="PATH_OR_URL", default=None,
                   help="a device speaking docs/device-protocol.md: a serial port, a pty or a pyserial URL "
                        "(socket://HOST:PORT); default: the simulated device")
    p.add_argument("--device-latency", type=int, default=None, metavar="SAMPLES",
                   help="samples the host answers ahead of the device's sensor sample: the packet to 1024 "
                        "(default 5)")
    p.add_argument("--device-packet", type=int, default=None, metavar="SAMPLES",
                   help="samples per sensor frame (default 1)")
    p.add_argument("--device-silence", type=float, default=None, metavar="SECONDS",
                   help="a device silent for longer is a device fault (default 0.02)")
    p.add_argument("--calibration", metavar="FILE", default=None,
                   help="calibrations keyed by serial number (TOML; default: the device's own)")
    p.add_argument("--json", action="store_true", help="print one JSON object at exit")
    p.set_defaults(func=run)


def _estimators(text, source):
    from studyapp import estimators
    from studyapp.errors import ParameterError
    from studyapp.estimators import lvt
    from studyapp.model.sources import PSEUDO_SOURCES, is_pseudo

    if text is None:
        if is_pseudo(source):
            return {}
        if source not in estimators.names():
            raise ParameterError(f"source {source!r}: allowed are {', '.join(PSEUDO_SOURCES)} or an estimator "
                                 f"({', '.join(n for n in estimators.names() if n != lvt.NAME)})")
        return {source: {}}
    if text.strip().lower() == "all":
        return {n: {} for n in estimators.names() if n != lvt.NAME}
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise ParameterError(f"--estimators {text!r}: names no estimator: allowed are comma-separated names from "
                             f"{', '.join(estimators.names())}, or all")
    unknown = [n for n in names if n not in estimators.names()]
    if unknown:
        raise ParameterError(f"--estimators: unknown {unknown[0]!r}; allowed are {', '.join(estimators.names())} or all")
    return {n: {} for n in names}


def _line(snap, elapsed):
    return (f"live: {elapsed:5.0f} s  rate {snap['achieved_rate']:.0f}/{snap['rate']:.0f} Hz  "
            f"load {100 * snap['load_mean']:.0f}% (max {100 * snap['load_max']:.0f}%)  "
            f"misses {snap['deadline_misses']}  underruns {snap['audio_underruns']}  "
            f"faults {snap['faults']}  F_max {snap['fmax']:.2f} N  source {snap['source']}")


def _check_device(args):
    """The link, its handshake and the link options, checked before the engine (and numba) loads: a bad link is
    one line and exit 2 within seconds."""
    from studyapp.device.link_open import is_link
    from studyapp.device.link_probe import probe
    from studyapp.errors import ParameterError

    if not is_link(args.device):
        raise ParameterError(f"--device {args.device}: allowed is a serial port, a pty or a pyserial URL")
    if args.device_silence is not None:
        from studyapp.device.handshake import check_silence

        check_silence(args.device_silence)
    from studyapp.device import source_channels
    from studyapp.model.sources import LVT_SENSOR

    options = {"packet": args.device_packet, "latency": args.device_latency}
    found = probe(args.device, args.rate, calibration=args.calibration,
                  **{key: value for key, value in options.items() if value is not None})
    source_channels.check([args.source or LVT_SENSOR], found["channels"], args.device)


def _device(info, summary):
    if info is None:
        return None
    return {**info, "health": summary.get("device_health"), "fault": summary.get("device_fault"),
            "rearms": summary.get("device_rearms", 0), "rearm_max_s": summary.get("device_rearm_max_s")}


def run(args):
    if args.device is not None:
        _check_device(args)
    import json
    import signal
    import sys
    import time

    from studyapp.cli import output_paths
    from studyapp.engine.config import EngineConfig
    from studyapp.engine.engine import Engine
    from studyapp.errors import ParameterError
    from studyapp.model.sources import LVT_SENSOR

    if args.source is None:
        args.source = LVT_SENSOR
    if args.seconds is not None and not args.seconds > 0:
        raise ParameterError(f"--seconds {args.seconds}: allowed is a positive number")
    output_paths.check_audio(args.audio, inputs=[args.protocol] if args.protocol else [])

    def say(text):
        print(text, file=sys.stderr, flush=True)

    config = EngineConfig(
        rate=args.rate, estimators=_estimators(args.estimators, args.source), source=args.source,
        fmax=args.fmax, gesture=args.gesture, seed=args.seed, block=args.block, audio=args.audio,
        midi=args.midi, device=args.device, device_calibration=args.calibration,
        device_rearm=True,  # a watchdog trip is re-armed at once, counted and told (a session leaves it to Resume)
    )
    link_options = (args.device_latency, args.device_packet, args.device_silence, args.calibration)
    if args.device is None and link_options != (None,) * 4:
        raise ParameterError("--device-latency, --device-packet, --device-silence and --calibration need "
                             "--device PATH_OR_URL")
    if args.device is not None:
        config.device_latency = config.device_latency if args.device_latency is None else args.device_latency
        config.device_packet = config.device_packet if args.device_packet is None else args.device_packet
        config.device_silence = config.device_silence if args.device_silence is None else args.device_silence
    if args.protocol is not None:
        from studyapp.engine.safety import SafetyLimits
        from studyapp.experiment.protocol import load_protocol

        config.safety = SafetyLimits(fmax_ceiling=load_protocol(args.protocol).fmax_ceiling)
    engine = Engine(config, on_notice=lambda notice: say(notice.text),
                    on_fault=lambda text: say(f"live: fault: {text}"))

    def terminate(signum, frame):
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, terminate)
    summary = None
    try:
        engine.start()
        info = engine.info
        say(f"live: {info['rate']:g} Hz, block {info['block']}, paced by the {info['paced']}, "
            f"audio {info['audio']}, MIDI {info['midi']}, real-time priority {'yes' if info['realtime'] else 'no'}")
        if info.get("device"):
            d = info["device"]
            say(f"live: device {d['name']} serial {d['serial']} (protocol {d['protocol']}, firmware {d['firmware']}) "
                f"on {d['link']}: latency {d['latency_samples']} samples, round trip {d['round_trip_ms']['median']:.2f} "
                f"ms (p99 {d['round_trip_ms']['p99']:.2f}), calibration {d['calibration']}")
        started = time.monotonic()
        next_line = started + 1.0
        while engine.alive:
            now = time.monotonic()
            if args.seconds is not None and now - started >= args.seconds:
                break
            if now >= next_line:
                say(_line(engine.status(), now - started))
                next_line += 1.0
            wake = next_line if args.seconds is None else min(next_line, started + args.seconds)
            time.sleep(max(0.0, min(0.1, wake - time.monotonic())))
    except KeyboardInterrupt:
        say("live: stopping")
    finally:
        summary = engine.stop() or {}
        signal.signal(signal.SIGTERM, previous)
    result = {
        "rate": config.rate,
        "achieved_rate": summary.get("achieved_rate", 0.0),
        "deadline_misses": summary.get("deadline_misses", 0),
        "audio_underruns": summary.get("audio_underruns", 0),
        "faults": list(engine.faults),
        "midi_messages": summary.get("midi_messages", 0),
        "events_dropped": engine.events_dropped,
        "seconds": summary.get("seconds", 0.0),
        "block": engine.info.get("block"),
        "load_max": summary.get("load_max", 0.0),
        "audio_xruns": summary.get("audio_xruns", 0),
        "command_latency_max": summary.get("command_latency_max", 0.0),
        "audio": engine.info.get("audio"),
        "midi": engine.info.get("midi"),
        "device": _device(engine.info.get("device"), summary),
    }
    if args.json:
        print(json.dumps(result))
    else:
        say(f"live: done: {result['achieved_rate']:.0f} Hz achieved, {result['deadline_misses']} deadline misses, "
            f"{result['audio_underruns']} underruns, {len(result['faults'])} faults, "
            f"{result['events_dropped']} events dropped")
    device = result["device"]
    if device is not None and device["health"] is not None:
        say(f"live: device: {device['health']['trips']} watchdog trips, {device['health']['silences']} silences, "
            f"{device['rearms']} re-armed"
            + (f" (the slowest {1e3 * device['rearm_max_s']:.0f} ms after the trip was read)"
               if device["rearm_max_s"] is not None else "")
            + (f"; latched: {device['fault']}" if device["fault"] else ""))
    return 1 if engine.tripped else 0
