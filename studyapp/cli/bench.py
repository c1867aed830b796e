"""``studyapp bench estimators|loop|live|midi|memory|force-cut|heartbeat|device``: speed and memory, measured, never asserted in tests."""


def register(sub):
    parser = sub.add_parser("bench", help="measure speed: estimators, closed loop, live engine, MIDI flood")
    kinds = parser.add_subparsers(dest="bench", metavar="WHAT", required=True)

    p = kinds.add_parser("estimators", help="ns per sample of every estimator and of the bank")
    p.add_argument("--rate", type=float, default=48_000.0, help="sample rate in Hz (default 48000)")
    p.add_argument("--samples", type=int, default=100_000, metavar="N",
                   help="samples per timed run (default 100000)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.estimators.benchmark"))

    p = kinds.add_parser("loop", help="closed-loop throughput with all fourteen estimators; with --core, the "
                                      "loop's cost in C and in numba")
    p.add_argument("--rate", type=float, default=48_000.0, help="sample rate in Hz (default 48000)")
    p.add_argument("--core", action="append", metavar="CORE",
                   help="c, numba or c,numba (repeatable): ns per sample of the loop and of its estimator bank "
                        "on each core, on a recorded sensor stream, instead of the simulated loop's throughput")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_loop)

    p = kinds.add_parser("live", help="highest rate the live engine holds in real time")
    p.add_argument("--seconds", type=float, default=30.0, help="confirmation run length (default 30)")
    p.add_argument("--block-ms", type=float, default=2.0,
                   help="block period in ms, the deadline of each block (default 2, the engine's)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.engine.benchmark"))

    p = kinds.add_parser("midi", help="the live engine under a flood of MIDI control changes (dummy JACK)")
    p.add_argument("--rate", type=float, default=10_000.0, help="control changes per second (default 10000)")
    p.add_argument("--seconds", type=float, default=5.0, help="flood length per run (default 5)")
    p.add_argument("--runs", type=int, default=3, help="runs; the figures are their medians (default 3)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.engine.midi_flood"))

    p = kinds.add_parser("memory", help="peak memory of 'studyapp estimate' on a generated CSV and .npz, "
                                        "or of 'studyapp simulate'")
    p.add_argument("--command", choices=("estimate", "simulate"), default="estimate",
                   help="the command measured (default estimate)")
    p.add_argument("--rows", type=int, default=10_000_000, metavar="N",
                   help="estimate: samples per input (default 10^7)")
    p.add_argument("--block", type=int, default=1 << 16, metavar="N",
                   help="estimate: its --block (default 65536, its own default)")
    p.add_argument("--rate", type=float, default=96_000.0, help="simulate: sample rate in Hz (default 96000)")
    p.add_argument("--duration", type=float, nargs="+", default=[1.0, 600.0], metavar="S",
                   help="simulate: seconds, one run each (default 1 600)")
    p.add_argument("--format", choices=("npz", "h5", "csv"), default="npz", help="simulate: output format "
                                                                                 "(default npz)")
    p.add_argument("--dir", metavar="DIR", help="where the temporary inputs go (default: the system's temp folder)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.cli.memory_benchmark"))

    p = kinds.add_parser("force-cut", help="time from a stopped worker to its force cut, with the parent busy")
    p.add_argument("--tries", type=int, default=20, metavar="N", help="tries per mode (default 20)")
    p.add_argument("--busy", type=float, default=2.0, help="seconds the parent stays busy (default 2)")
    p.add_argument("--mode", choices=("python", "gil", "both", "owner-stop", "owner-kill", "owner"), default="both",
                   help="python: a pure-Python loop; gil: one C call holding the interpreter's lock (default both); "
                        "owner-stop, owner-kill (owner: both): stop or kill the process that started the engine")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.engine.force_cut_benchmark"))

    p = kinds.add_parser("heartbeat", help="the engine's heartbeat silences and watchdog trips under this machine's load")
    p.add_argument("--seconds", type=float, default=60.0, help="run length (default 60)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.engine.heartbeat_benchmark"))
    p = kinds.add_parser("device", help="the loop over a pty to the device emulator: frames on time, host turnaround; "
                                                 "--loop device: watchdog trips, force gaps, telemetry, CONTROL delivery")
    p.add_argument("--seconds", type=float, default=60.0, help="timed run length (default 60)")
    p.add_argument("--runs", type=int, default=1, help="runs; the figures are their medians (default 1)")
    p.add_argument("--rate", type=float, default=5000.0, help="the device's rate in Hz (default 5000)")
    p.add_argument("--latency", type=int, default=5, metavar="SAMPLES",
                   help="samples the host answers ahead: the packet to 1024 (default 5: 1 ms at 5 kHz)")
    p.add_argument("--packet", type=int, default=None, metavar="SAMPLES",
                   help="samples per sensor (host loop) or telemetry (device loop) frame (default 1; 10 for a "
                        "device loop)")
    p.add_argument("--watchdog-ms", type=int, default=1, help="the emulator's watchdog in ms (default 1)")
    p.add_argument("--loop", default="host", metavar="host|device",
                   help="who runs the loop: the host, answering each sensor frame (protocol 1, the default), or "
                        "the device (protocol 2: telemetry, the host's shadow, CONTROL on a knob turn)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_run("studyapp.device.benchmark"))


def _loop(args):
    return _run("studyapp.device.loop_benchmark" if args.core else "studyapp.model.benchmark")(args)


def _run(module):
    def run(args):
        import importlib

        return importlib.import_module(module).run_cli(args)

    return run
