"""``studyapp device-emulator``: a device that speaks the device protocol on a pty, for hosts and tests.

    studyapp device-emulator --link PATH [--rate HZ] [--seed N] [--gesture strokes|hold]
        [--latency S] [--jitter S] [--loss P] [--corrupt P] [--disconnect-after S] [--lockstep]
        [--format f64|counts] [--core auto|c|python] [--watchdog-ms MS]
        [--loop host|device] [--keepalive-ms MS] [--first-sample N]

Makes PATH a link to the device end of a new pty (as socat does) and prints
``ready: PATH`` once it exists; runs until SIGTERM / Ctrl-C (or
``--disconnect-after``), removes the link and prints ``stats: {json}``.
studyapp/device/emulator.py says what it simulates; docs/device-protocol.md
what it speaks. ``--loop device`` runs the loop on the device (protocol version 2,
in C: not with ``--core python``), its watchdog on the host's keep-alive
(``--keepalive-ms``, default 200) instead of ``--watchdog-ms``. ``--first-sample``
starts the device's u32 sample counter there (4294962296 = 2^32 - 5000: the
counter wraps 1 s into the stream at 5 kHz). A bad option:
one line, exit 2, no link made.
"""

from studyapp.cli import number_options

RATE_RANGE = (100, 100000)


def register(sub):
    p = sub.add_parser("device-emulator", help="emulate a device speaking the device protocol on a pty link")
    p.add_argument("--link", required=True, metavar="PATH", help="the path to make a link to the pty's device end")
    p.add_argument("--rate", metavar="HZ", type=float, default=5000.0,
                   help=f"sample rate in Hz, a whole number {RATE_RANGE[0]}..{RATE_RANGE[1]} (default 5000)")
    p.add_argument("--seed", metavar="N", type=number_options.seed, default=0,
                   help="sensor noise and link faults (default 0)")
    p.add_argument("--gesture", metavar="strokes|hold", default="strokes",
                   help="the virtual hand's gesture (default strokes)")
    p.add_argument("--latency", metavar="S", type=float, default=0.0,
                   help="seconds the device's received frames are delayed")
    p.add_argument("--jitter", metavar="S", type=float, default=0.0, help="extra delay, uniform over 0..S seconds")
    p.add_argument("--loss", metavar="P", type=float, default=0.0, help="probability a frame is lost (either way)")
    p.add_argument("--corrupt", metavar="P", type=float, default=0.0,
                   help="probability a frame has a bit flipped (either way)")
    p.add_argument("--disconnect-after", metavar="S", type=float, default=None, help="close the link after S seconds")
    p.add_argument("--lockstep", action="store_true",
                   help="no clock: advance only once the force tagged for the sample is in (tests)")
    p.add_argument("--format", metavar="f64|counts", default="f64",
                   help="sensor channels: f64 in SI, or counts (i32 with a gain) (default f64)")
    p.add_argument("--core", metavar="auto|c|python", default="auto",
                   help="firmware core: auto is C if it builds (default auto)")
    p.add_argument("--watchdog-ms", metavar="MS", type=int, default=None,
                   help="the device's watchdog, 1..1000 ms (default 1; a host loop's)")
    p.add_argument("--loop", metavar="host|device", default="host",
                   help="who runs the loop: the host (protocol 1, default) or the device (protocol 2, the C loop)")
    p.add_argument("--keepalive-ms", metavar="MS", type=int, default=None,
                   help="a device loop's watchdog on the host's keep-alive, 1..65535 ms (default 200)")
    p.add_argument("--first-sample", metavar="N", type=int, default=0,
                   help="the device's u32 sample counter starts at N, 0..4294967295 (default 0; near 2^32 it wraps "
                        "while streaming)")
    p.set_defaults(func=run)


def config_from(args):
    from studyapp.device.emulator import CORES, FORMATS, GESTURES, KEEPALIVE_MS, LOOPS, EmulatorConfig
    from studyapp.device.pty_link import check_path
    from studyapp.errors import UserError

    def need(ok, text):
        if not ok:
            raise UserError(text)

    need(args.rate == int(args.rate) and RATE_RANGE[0] <= args.rate <= RATE_RANGE[1],
         f"--rate {args.rate:g}: allowed is a whole number of Hz from {RATE_RANGE[0]} to {RATE_RANGE[1]}")
    need(args.gesture in GESTURES, f"--gesture {args.gesture!r}: allowed are {', '.join(GESTURES)}")
    need(args.format in FORMATS, f"--format {args.format!r}: allowed are {', '.join(FORMATS)}")
    need(args.core in CORES, f"--core {args.core!r}: allowed are {', '.join(CORES)}")
    for name in ("latency", "jitter"):
        value = getattr(args, name)
        need(0.0 <= value <= 10.0, f"--{name} {value:g}: allowed is 0 to 10 seconds")
    for name in ("loss", "corrupt"):
        value = getattr(args, name)
        need(0.0 <= value <= 1.0, f"--{name} {value:g}: allowed is a probability from 0 to 1")
    need(args.disconnect_after is None or args.disconnect_after > 0.0,
         f"--disconnect-after {args.disconnect_after}: allowed is a number of seconds above 0")
    need(args.loop in LOOPS, f"--loop {args.loop!r}: allowed are {', '.join(LOOPS)}")
    device_loop = args.loop == "device"
    need(not (device_loop and args.core == "python"),
         "--loop device with --core python: the device's loop is the C one (firmware/studyapp_loop.c); "
         "allowed: --core auto or c")
    need(not (device_loop and args.watchdog_ms is not None),
         "--watchdog-ms with --loop device: a device loop's watchdog is the keep-alive's (--keepalive-ms)")
    need(device_loop or args.keepalive_ms is None,
         "--keepalive-ms with --loop host: the keep-alive watchdog is a device loop's (--loop device)")
    watchdog_ms = 1 if args.watchdog_ms is None else args.watchdog_ms
    keepalive_ms = KEEPALIVE_MS if args.keepalive_ms is None else args.keepalive_ms
    need(1 <= watchdog_ms <= 1000, f"--watchdog-ms {watchdog_ms}: allowed is 1 to 1000")
    need(1 <= keepalive_ms <= 65535, f"--keepalive-ms {keepalive_ms}: allowed is 1 to 65535")
    faults = [n for n in ("latency", "jitter", "loss", "corrupt") if getattr(args, n)]
    need(not (args.lockstep and faults),
         f"--lockstep with --{faults[0] if faults else ''}: lock-step waits for every force, so it takes no "
         "link faults (allowed: --disconnect-after)")
    need(0 <= args.first_sample <= 0xFFFFFFFF,
         f"--first-sample {args.first_sample}: allowed is a whole number from 0 to 4294967295 (a u32 counter)")
    check_path(args.link)
    return EmulatorConfig(link=args.link, rate=int(args.rate), seed=args.seed, gesture=args.gesture,
                          latency=args.latency, jitter=args.jitter, loss=args.loss, corrupt=args.corrupt,
                          disconnect_after=args.disconnect_after, lockstep=args.lockstep, format=args.format,
                          core=args.core, watchdog_ms=watchdog_ms, loop=args.loop, keepalive_ms=keepalive_ms,
                          first_sample=args.first_sample)


def run(args):
    config = config_from(args)
    from studyapp.device.emulator import Emulator
    return Emulator(config).run()
