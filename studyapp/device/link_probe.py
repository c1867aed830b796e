"""Is this link a device that fits the loop? Checked in seconds, before anything heavy is loaded.

``probe(spec, rate, packet, calibration)`` opens the link (link_open.py: a
character device or a URL that answers), shakes hands (handshake.py: HELLO ->
INFO checked, bounded timeouts, two PINGs) and closes it again, importing
neither numba nor the loop, so that ``studyapp live --device`` refuses a bad
link with one line and exit code 2 within seconds even on a loaded machine
(a silent one after ``handshake.HELLO_WAIT``, the time a board may take to boot).
Returns the INFO's summary (name, serial, round trip, protocol, the channels
it sends, and who runs the loop: "host" or "device", protocol 2); the worker opens the link again
for the run (a device answers every HELLO with INFO), with the driver that
fits it (device_open.py).
"""

import time
from collections import namedtuple

from studyapp.device import handshake
from studyapp.device import loop_messages as lm
from studyapp.device import messages as msg
from studyapp.device.errors import ProtocolError
from studyapp.device.frames import FrameReader, encode
from studyapp.device.link_open import open_link
from studyapp.model.limits import IMPULSIVE_FORCE, SUSTAINED_FORCE

MotorLimits = namedtuple("MotorLimits", "impulsive sustained")
MOTOR = MotorLimits(IMPULSIVE_FORCE, SUSTAINED_FORCE)


def probe(spec, rate, packet=1, calibration=None, latency=1, ramp_ms=0):
    """``{"name", "serial", "round_trip_ms"}`` of the device on ``spec``; ``ParameterError`` (one line) if it is none."""
    packet = handshake.check_packet(packet)
    handshake.check_latency(latency, packet)
    handshake.check_ramp(ramp_ms)
    link = open_link(spec)
    reader = FrameReader()
    seq = [0]
    channels = [None]
    inbox = []

    def send(message):
        link.write(encode(message.pack(seq[0])))
        seq[0] = (seq[0] + 1) & 0xFF

    def receive(timeout):
        end = time.monotonic() + timeout
        while True:
            if inbox:
                return inbox.pop(0)
            corrupt = reader.corrupt
            for payload in reader.feed(link.read()):
                try:
                    _, message = lm.parse(payload, channels[0])
                except ProtocolError as exc:
                    if payload[0] == msg.INFO:
                        inbox.append(handshake.BadFrame(str(exc), True))
                    continue
                if not isinstance(message, (msg.Sensors, lm.Telemetry)):
                    inbox.append(message)
            if reader.corrupt > corrupt:
                inbox.append(handshake.BadFrame(reader.last_error, False))
            if inbox:
                continue
            left = end - time.monotonic()
            if left <= 0 or not link.wait(left):
                return None

    try:
        info, scales = handshake.greet(send, receive, spec, float(rate), MOTOR, packet, calibration)
        channels[0] = info.channels
        round_trip = handshake.probe(send, receive, spec, 2)
        send(msg.Stop())
    except (OSError, EOFError) as exc:
        from studyapp.errors import ParameterError

        raise ParameterError(f"device at {spec}: the link failed during the handshake ({exc})") from None
    finally:
        link.close()
    loop = handshake.loop_of(info, spec)
    return {"name": info.name, "serial": info.serial, "calibration": scales.source, "round_trip_ms": round_trip,
            "channels": list(scales.kinds),
            "protocol": info.protocol_version, "loop": "device" if loop.loop == lm.DEVICE_LOOP else "host",
            "estimator_kinds": list(loop.kinds)}
