"""A device's firmware loop in Python: bytes in, one sample at a time, bytes out.

The mirror of firmware/studyapp_device.c (c_core.py loads that), with the
same interface, so that the emulator runs either and the tests hold them
equal byte for byte:

    rx(data)          bytes from the host, arrived before the current sample's actuation
    sample(raw)       the current sample's sensor values, one per INFO channel (f64: SI; counts: integers)
    needs_force()     streaming and the force tagged for the current sample not here yet (lock-step)
    actuate() -> F    the force over [now, now + 1] (N), by the safety core (device_side.py); advances now
    tx() -> bytes     the frames to send, oldest first

The host's frames are checked (frames.py), parsed (messages.py) and applied
in arrival order: HELLO -> INFO; PING -> PONG(nonce, now); ARM, DISARM,
START, STOP -> applied, then STATE; FORCE -> stored by tag; KEEPALIVE feeds
the watchdog. A START whose packet exceeds INFO's max_packet is corrupt.
While streaming, SENSORS goes out once ``packet`` samples are in, stamped
with the first one's counter. The safety core's reports go out as FAULT.
A gap in the host's ``seq`` counts as ``lost``, except at a HELLO, which starts a new
conversation (a host that reopens the link starts its seq at 0 again).
"""

from studyapp.device import messages
from studyapp.device.device_side import DeviceSide, SafetyConfig
from studyapp.device.errors import ProtocolError
from studyapp.device.frames import FrameReader
from studyapp.device.streams import Sender


class Firmware:
    """The device protocol's firmware loop around the safety core, for the device described by ``info``."""

    def __init__(self, info):
        self.info = info
        self.side = DeviceSide(SafetyConfig.from_info(info))
        self._reader = FrameReader()
        self._sender = Sender(info.channels)
        self._out = bytearray()
        self._rows = []
        self._packet = 1
        self._last_seq = None
        self.lost = 0

    @property
    def now(self):
        return self.side.now

    def rx(self, data):
        data = bytes(data)
        start = 0
        while start < len(data):
            end = data.find(b"\x00", start)
            end = len(data) if end < 0 else end + 1
            before = self._reader.corrupt
            payloads = self._reader.feed(data[start:end])
            if self._reader.corrupt > before:
                self.side.corrupt_frame()
                self._reports()
            for payload in payloads:
                self._payload(payload)
                self._reports()
            start = end

    def _payload(self, payload):
        try:
            if payload[0] not in messages.HOST_TYPES:
                raise ProtocolError(f"type 0x{payload[0]:02x}: not a host message")
            seq, message = messages.parse(payload)
            if isinstance(message, messages.Start) and message.packet > self.info.max_packet:
                raise ProtocolError(f"START.packet = {message.packet}: above max_packet {self.info.max_packet}")
        except ProtocolError:
            self.side.corrupt_frame()
            return
        if self._last_seq is not None and not isinstance(message, messages.Hello):  # HELLO: a new conversation
            self.lost += (seq - self._last_seq - 1) & 0xFF
        self._last_seq = seq
        side = self.side
        side.valid_frame(message)
        if isinstance(message, messages.Force):
            side.force(message.sample, message.forces)
        elif isinstance(message, messages.Hello):
            self._send(self.info)
        elif isinstance(message, messages.Ping):
            self._send(messages.Pong(message.nonce, side.now))
        elif isinstance(message, messages.Keepalive):
            pass
        else:
            if isinstance(message, messages.Arm):
                side.arm(message.ramp_ms)
            elif isinstance(message, messages.Disarm):
                side.disarm(message.reason)
            elif isinstance(message, messages.Start):
                self._packet = message.packet
                self._rows = []
                side.start(message.packet, message.latency)
            elif isinstance(message, messages.Stop):
                self._rows = []
                side.stop()
            self._send(self.state())

    def state(self):
        s = self.side
        return messages.State(int(s.armed), int(s.streaming), s.fault, s.late & 0xFFFFFFFF, self.lost & 0xFFFFFFFF,
                              s.corrupt & 0xFFFFFFFF)

    def _send(self, message):
        self._out += self._sender.frame(message)

    def _reports(self):
        for code, sample, detail in self.side.reports:
            self._send(messages.Fault(code, sample, detail))
        self.side.reports.clear()

    def sample(self, raw):
        if not self.side.streaming:
            return
        self._rows.append(tuple(raw))
        if len(self._rows) == self._packet:
            first = (self.side.now - self._packet + 1) & 0xFFFFFFFF
            self._send(messages.Sensors(first, self.side.take_flags(), tuple(self._rows)))
            self._rows = []

    def needs_force(self):
        return self.side.needs_force()

    def actuate(self):
        f = self.side.actuate()
        self._reports()
        return f

    def tx(self):
        out = bytes(self._out)
        self._out.clear()
        return out

    def streaming(self):
        return self.side.streaming

    def busy(self):
        """Armed or streaming: the emulator paces such samples closely."""
        return self.side.streaming or self.side.armed

    def set_counter(self, sample):
        """The sample counter from ``sample`` (u32) on: before START (the emulator's --first-sample)."""
        self.side.set_counter(sample)

    def counters(self):
        s = self.side
        return {"now": s.now, "armed": int(s.armed), "streaming": int(s.streaming), "fault": s.fault,
                "late": s.late, "lost": self.lost, "corrupt": s.corrupt, "missing": s.missing}
