"""``studyapp firmware-params --rate HZ -o FILE.h``: the C header a lab's firmware builds its device loop from.

The host's own loop for a device that runs it (protocol version 2;
device/loop_bank.py: the study's estimators with Table 1's parameters at
the rate, the string, the motor limits), written exactly as C99
initialisers, with the INFO the device answers HELLO with (its image CRC
is the host's). firmware/example_isr.c is a firmware built on it;
docs/devices.md, "Bringing your own device", says how. ``--format counts``:
the channels as i32 counts of 1 nm, 1 um/s^2 and 10 nm/s (the emulator's);
``--no-accelerometer``: no acceleration channel and no estimator that reads one.
"""


def register(sub):
    from studyapp.cli.device_emulator import RATE_RANGE
    from studyapp.device.firmware_params import FORMATS

    p = sub.add_parser("firmware-params", help="write the C header of the host's loop for a lab's device firmware")
    p.add_argument("--rate", metavar="HZ", type=float, default=5000.0,
                   help=f"the device's sample rate, a whole number {RATE_RANGE[0]}..{RATE_RANGE[1]} (default 5000)")
    p.add_argument("--format", choices=FORMATS, default="f64", help="how the channels are sent (default f64)")
    p.add_argument("--no-accelerometer", action="store_true", help="the device has no accelerometer")
    p.add_argument("--name", default="studyapp device loop", help="INFO's name (at most 32 bytes of UTF-8)")
    p.add_argument("--serial", default="LAB-0001", help="INFO's serial: the host's calibration file's key")
    p.add_argument("-o", "--output", metavar="FILE.h", required=True, help="the header to write (a new file)")
    p.set_defaults(func=run)


def run(args):
    import shlex
    import sys
    from pathlib import Path

    from studyapp.cli import output_paths
    from studyapp.cli.device_emulator import RATE_RANGE
    from studyapp.device import firmware_params, loop_bank, messages
    from studyapp.device.emulator import COUNT_CHANNELS
    from studyapp.device.errors import ProtocolError
    from studyapp.errors import UserError
    from studyapp.io.atomic import atomic_open

    if not (args.rate == int(args.rate) and RATE_RANGE[0] <= args.rate <= RATE_RANGE[1]):
        raise UserError(f"--rate {args.rate:g}: allowed is a whole number of Hz from {RATE_RANGE[0]} to {RATE_RANGE[1]}")
    output_paths.check_file(args.output)
    if Path(args.output).exists():
        raise UserError(f"-o {args.output}: exists; allowed is a new file (a firmware's header is not overwritten)")
    rate, accelerometer = int(args.rate), not args.no_accelerometer
    channels = COUNT_CHANNELS if args.format == "counts" else messages.SI_CHANNELS
    if not accelerometer:
        channels = tuple(c for c in channels if c.kind != messages.ACCELERATION)
    loop = loop_bank.device_loop(rate, accelerometer)
    try:
        info = firmware_params.device_info(rate, loop, args.name, args.serial, channels)
        info.pack()
    except ProtocolError as exc:
        raise UserError(f"--name/--serial: {exc}") from None
    command = " ".join(["studyapp firmware-params", f"--rate {rate}", f"--format {args.format}",
                        *(["--no-accelerometer"] if args.no_accelerometer else []),
                        f"--name {shlex.quote(args.name)}", f"--serial {shlex.quote(args.serial)}",
                        f"-o {shlex.quote(Path(args.output).name)}"])
    with atomic_open(args.output) as f:
        f.write(firmware_params.header_text(rate, info, loop, command))
    print(f"studyapp firmware-params: {args.output}: the device loop at {rate} Hz, "
          f"{len(loop.bank.kinds)} estimators", file=sys.stderr)
    return 0
