"""MIDI knobs and pads in: python-rtmidi (JACK MIDI, else the ALSA sequencer), parsed by mido.

The paper's participants turned the knobs of an Akai LPD8 (7-bit potentiometers,
footnote 3). ``ControlMap`` turns a MIDI message into ``(control, value)`` with
value in [0, 1]:

- ``ControlMap.lpd8()``: the LPD8 factory preset, knobs ``knob1..knob8`` on
  control changes 1-8 and pads ``pad1..pad8`` on notes 36-43, all on channel 1;
- ``ControlMap.from_protocol({"knob1": {"cc": 7, "channel": 1}, "pad1": {"note": 60}})``;
- ``learn(control)``: the next control change or note binds to ``control``.

``open_input(spec)`` opens an input: ``"virtual"`` makes a port others connect
to, ``"first"`` takes the first source found, any other text picks the first
port whose name contains it, ``"none"`` opens nothing.

**Hot-plug.** When JACK runs but no port matches yet (``"first"`` or a
name), ``open_input`` opens an input port of its own that nothing feeds yet
(``MidiInput.waiting``, its ``inlet`` named by a client unique to the
process) and the parent connects the controller to it once one appears
(``midi_hotplug.MidiHotplug``); ``connected(port)`` then names it. The worker
never looks for ports itself: python-rtmidi holds the GIL for the whole of
a call, and a JACK request (listing or connecting ports) took 36 us typically
but up to 14-240 ms on a loaded machine (measured on a dummy server), long
enough to miss many blocks and trip the watchdog. ALSA is not rescanned. No Python runs on
rtmidi's thread: it puts each message on its own C++ queue
(``queue_size_limit`` = ``QUEUE`` messages, 3.3 s at 10,000 messages/s) and the
engine polls that queue at block boundaries (``MidiInput.poll``), then
coalesces control changes (``coalesce``: the last value of each controller in
a block) and parses only what is left. (A Python callback, even one that only
queued the raw bytes, took the GIL from the loop once per message: at 10,000
messages/s, tens of deadline misses in 5 s; parsing in it, as mido's own
ports do, cost ~10 us of GIL per message more.) Without a back-end (these
machines have no ALSA sequencer, and JACK needs a running server)
``open_input`` prints one line and returns ``None``: the on-screen knobs take
over.

**Arrival times.** rtmidi gives each message its delta time d_i, the seconds
since the message before it, on its own clock (JACK: the time of the process
cycle that delivered it, in microseconds; so messages delivered in one cycle
share a time). A poll at time T (``time.monotonic()``) that empties the queue
takes messages 1..n, all of which arrived after the previous poll at T_prev
(it emptied the queue too). ``arrival_times`` anchors the last at T and goes
back by the delta times:

    a_n = T,   a_i = max(a_{i+1} - d_{i+1}, T_prev)   (i = n-1 .. 1)

Since the true arrival r_n lies in (T_prev, T], every a_i is late by the same
e = T - r_n, 0 <= e < T - T_prev, i.e. at most one block period (plus any
lateness of the wake-up) when the loop keeps time; the clamp at T_prev only
moves a_i towards the truth. The knob-to-effect latencies measured from a_i
are short by e at most. If rtmidi's queue overflowed, it dropped the newest
messages (it prints a line on stderr, the only sign it gives), so a poll
that finds ``QUEUE`` messages or more counts one ``overflow``.
"""

import os
import time

import mido

from studyapp.engine.midi_bytes import split
from studyapp.engine.native_stderr import captured_native_stderr
from studyapp.errors import ParameterError
from studyapp.model.controls import knob_value

CLIENT = "studyapp"
VIRTUAL_PORT = "studyapp MIDI in"
APIS = ("UNIX_JACK", "LINUX_ALSA")
CONTROL_CHANGE = 0xB0  # status byte's high nibble
QUEUE = 2**15  # rtmidi's queue, messages: seconds at 10,000/s, beyond any stall the watchdog lets pass
RESCAN = 2.0  # s between two looks for a controller plugged in (or out), midi_hotplug.py
FLUSH = 0.02  # s between two lone F7 to our own port (JACK): a SysEx left open holds messages at most this long
ENDS_SYSEX = [0xF7]
FLUSH_PORT = "studyapp SysEx end"  # the output port that sends it


def _key(kind, channel, number):
    if kind not in ("cc", "note"):
        raise ParameterError(f"MIDI map: kind {kind!r} is not cc or note")
    if not 1 <= channel <= 16:
        raise ParameterError(f"MIDI map: channel {channel} is outside 1..16")
    if not 0 <= number <= 127:
        raise ParameterError(f"MIDI map: {kind} number {number} is outside 0..127")
    return (kind, int(channel), int(number))


class ControlMap:
    """MIDI message -> ``(control, value in [0, 1])``; channels are 1..16 as printed on devices."""

    def __init__(self, bindings=None):
        self._by_key = {}
        self._by_control = {}
        self.learning = None
        for control, key in (bindings or {}).items():
            self.bind(control, *key)

    @classmethod
    def lpd8(cls):
        """The Akai LPD8 factory preset: knobs CC 1-8, pads notes 36-43, channel 1."""
        bindings = {f"knob{i}": ("cc", 1, i) for i in range(1, 9)}
        bindings.update({f"pad{i}": ("note", 1, 35 + i) for i in range(1, 9)})
        return cls(bindings)

    @classmethod
    def from_protocol(cls, mapping):
        """From ``{control: {"cc": n, "channel": c}}`` or ``{"note": n}`` (channel defaults to 1)."""
        if not isinstance(mapping, dict):
            raise ParameterError("MIDI map: expected a table of control: {cc|note: number, channel: 1..16}")
        bindings = {}
        for control, entry in mapping.items():
            if not isinstance(entry, dict) or len({"cc", "note"} & set(entry)) != 1:
                raise ParameterError(f"MIDI map: {control} needs exactly one of cc or note")
            unknown = set(entry) - {"cc", "note", "channel"}
            if unknown:
                raise ParameterError(f"MIDI map: {control} has unknown field {sorted(unknown)[0]!r}")
            kind = "cc" if "cc" in entry else "note"
            bindings[control] = (kind, entry.get("channel", 1), entry[kind])
        return cls(bindings)

    def bind(self, control, kind, channel, number):
        key = _key(kind, channel, number)
        old = self._by_control.pop(control, None)
        if old is not None:
            self._by_key.pop(old, None)
        taken = self._by_key.pop(key, None)
        if taken is not None:
            self._by_control.pop(taken, None)
        self._by_key[key] = control
        self._by_control[control] = key

    def learn(self, control):
        """Bind ``control`` to the next control change or note that arrives."""
        self.learning = str(control)

    def to_dict(self):
        return {c: {k: n, "channel": ch} for c, (k, ch, n) in self._by_control.items()}

    def lookup(self, msg):
        """``(control, value)`` for a mapped message, else ``None``; binds it first in learn mode."""
        if msg.type == "control_change":
            key, value = ("cc", msg.channel + 1, msg.control), knob_value(msg.value)
        elif msg.type == "note_on":
            key, value = ("note", msg.channel + 1, msg.note), (1.0 if msg.velocity > 0 else 0.0)
        elif msg.type == "note_off":
            key, value = ("note", msg.channel + 1, msg.note), 0.0
        else:
            return None
        if self.learning is not None and msg.type in ("control_change", "note_on"):
            self.bind(self.learning, *key)
            self.learning = None
        control = self._by_key.get(key)
        return None if control is None else (control, value)


def coalesce(received):
    """One block's raw ``(bytes, time, block)`` as ``(mido.Message, time, block)``, control changes coalesced.

    A control change sets a level, so only the last value of each controller
    (channel, number) in a block matters: it takes the place of the
    controller's first message, so controls keep the order in which they
    first moved (learn mode binds the first that moved). Notes (pads) and
    every other message stay, each one, in order: a press is an event, not a
    level. A flood of control changes then costs the loop at most one action
    per controller per block, and the event ring at most one control event.
    Each raw item is first split into whole messages (``midi_bytes.split``:
    an unterminated SysEx ends at the next status byte); messages mido cannot
    parse are left out.
    """
    kept = []
    slot = {}
    for item in ((message, arrived, block) for raw, arrived, block in received for message in split(raw)):
        raw = item[0]
        if raw and raw[0] & 0xF0 == CONTROL_CHANGE and len(raw) > 1:
            key = (raw[0], raw[1])
            if key in slot:
                kept[slot[key]] = item
                continue
            slot[key] = len(kept)
        kept.append(item)
    out = []
    for raw, arrived, block in kept:
        try:
            out.append((mido.Message.from_bytes(raw), arrived, block))
        except ValueError:
            continue
    return out


class MidiUnavailable(RuntimeError):
    """No MIDI back-end or no such port."""


def arrival_times(deltas, polled, previous):
    """Arrival times of one poll's messages from rtmidi's delta times (see module docstring).

    ``deltas``: each message's seconds since the message before it; ``polled``:
    the time of this poll (the last message is anchored there); ``previous``:
    the time of the poll before, which emptied the queue, so no message
    arrived before it.
    """
    times = [0.0] * len(deltas)
    at = polled
    for i in range(len(deltas) - 1, -1, -1):
        times[i] = at
        at = max(at - deltas[i], previous)
    return times


class MidiInput:
    """An open MIDI input; ``poll()`` returns the raw ``(bytes, arrival time, block)`` received since the last poll.

    ``block`` is the engine's block counter at arrival: the engine reports
    each new block with ``new_block(k, time)``.
    """

    def __init__(self, port, api, rt=None, queue_size=QUEUE, spec=None, inlet=None):
        self.port = port
        self.api = api
        self.spec = spec  # what the controller's port must match ("first" or part of a name)
        self.inlet = inlet  # our own port a controller is connected to from outside (hot-plug), or None
        self.queue_size = queue_size
        self.received = 0
        self.overflows = 0
        self.block = 0
        self._block_time = self._polled = self._flushed = time.monotonic()
        self._rt = rt
        self.flush = None  # JACK: an output to our own port that ends a SysEx left open (``FLUSH``)

    def new_block(self, k, at):
        """Block ``k`` starts counting at time ``at``: later messages arrived in it."""
        self.block, self._block_time = k, at

    def poll(self):
        if self._rt is None:
            return []
        get = self._rt.get_message  # C++ queue, no lock shared with Python
        messages = []
        while True:
            message = get()
            if message is None:
                break
            if message[0] != ENDS_SYSEX:  # our own flush, come back with nothing before it
                messages.append(message)
        polled, previous = time.monotonic(), self._polled
        if self.flush is not None and polled - self._flushed >= FLUSH:
            self._flushed = polled
            self.flush.send_message(ENDS_SYSEX)  # a ring buffer write: no request to the JACK server
        self._polled = polled
        if not messages:
            return []
        self.received += len(messages)
        if len(messages) >= self.queue_size:
            self.overflows += 1
        times = arrival_times([d for _, d in messages], polled, previous)
        # all arrived after the previous poll, so in the block now counted or in the one before
        k, since = self.block, self._block_time
        return [(raw, at, k if at >= since else k - 1) for (raw, _), at in zip(messages, times)]

    @property
    def waiting(self):
        """No controller connected yet (hot-plug: ``inlet`` waits for one)."""
        return self.port is None

    def connected(self, port):
        """The parent connected ``port`` to our ``inlet`` (None: it went away); returns a sentence saying so."""
        gone, self.port = self.port, port or None
        self._polled = time.monotonic()  # nothing arrived from it before now
        if self.port is not None:
            return f"MIDI: {self.port} plugged in; its knobs and pads act now"
        return f"MIDI: {gone} was unplugged; plugging it in again is picked up within {RESCAN:g} s"

    @property
    def description(self):
        api = "JACK" if self.api == "UNIX_JACK" else "ALSA"
        if self.port is None:
            return f"none yet ({api}): plugging a controller in is picked up within {RESCAN:g} s"
        return f"{self.port} ({api})"

    def close(self):
        if self.flush is not None:
            self.flush.close_port()
            self.flush.delete()
            self.flush = None
        if self._rt is not None:
            self._rt.close_port()
            self._rt.delete()
            self._rt = None


def match_port(spec, names):
    """The port ``spec`` picks among ``names`` ("first": the first one), or ``None``; never a ``FLUSH_PORT``
    (an engine's own output to its own input, not a controller)."""
    names = [n for n in names if not n.endswith(f":{FLUSH_PORT}")]
    if spec == "first":
        return names[0] if names else None
    return next((n for n in names if spec.lower() in n.lower()), None)


class NoPortYet(MidiUnavailable):
    """JACK runs but no port matches; ``waiting`` is an input whose ``inlet`` the parent connects later."""

    def __init__(self, text, waiting):
        super().__init__(text)
        self.waiting = waiting


def _open(spec, api, client):
    import rtmidi

    rtapi = getattr(rtmidi, f"API_{api}")
    if rtapi not in rtmidi.get_compiled_api():
        raise MidiUnavailable(f"python-rtmidi was built without {api}")
    rt = rtmidi.MidiIn(rtapi=rtapi, name=client, queue_size_limit=QUEUE)
    # clock and active sensing stay filtered out; SysEx is kept, for midi_bytes.split to end an open one
    rt.ignore_types(sysex=False, timing=True, active_sense=True)
    try:
        midi = MidiInput(None, api, queue_size=QUEUE)
        if spec == "virtual":
            rt.open_virtual_port(VIRTUAL_PORT)
            midi.port = f"{client}:{VIRTUAL_PORT}" if api == "UNIX_JACK" else VIRTUAL_PORT
            midi.flush = _flush_output(rtmidi, api, client)
        else:
            names = rt.get_ports()
            match = match_port(spec, names)
            midi.spec = spec
            if match is None:
                reason = f"no MIDI input matches {spec!r} (inputs: {', '.join(names) or 'none'})"
                if api != "UNIX_JACK":
                    raise MidiUnavailable(reason)
                rt.open_virtual_port(VIRTUAL_PORT)
                midi._rt, midi.inlet = rt, f"{client}:{VIRTUAL_PORT}"
                midi.flush = _flush_output(rtmidi, api, client)
                raise NoPortYet(reason, midi)
            rt.open_port(names.index(match), VIRTUAL_PORT)
            midi.port = match
            midi.flush = _flush_output(rtmidi, api, client)
    except NoPortYet:
        raise
    except BaseException:
        rt.delete()
        raise
    midi._rt = rt
    return midi


def _flush_output(rtmidi, api, client):
    """JACK: an output connected to our own input port ``client:VIRTUAL_PORT``, for ``FLUSH`` (else None).

    rtmidi's JACK input appends every event after an unterminated SysEx to it until an event ends in
    ``F7`` (midi_bytes.py); a lone ``F7`` sent now and then ends it, and what was held comes back."""
    if api != "UNIX_JACK":
        return None  # the ALSA sequencer hands over a SysEx whole: nothing is held
    out = rtmidi.MidiOut(rtapi=getattr(rtmidi, f"API_{api}"), name=f"{client}-flush")
    own = f"{client}:{VIRTUAL_PORT}"
    names = out.get_ports()
    if own not in names:
        out.delete()
        return None
    out.open_port(names.index(own), FLUSH_PORT)
    return out


def open_input(spec, say=print, client=CLIENT):
    """Open the MIDI input named by ``spec`` (see module docstring), or say why not and return ``None``."""
    spec = (spec or "none").strip()
    if spec == "none":
        return None
    reasons = []
    waiting = None  # JACK runs but has no such port yet: an inlet the parent connects a controller to
    for api in APIS:
        with captured_native_stderr():
            try:
                # a client name of our own: the parent connects to the inlet by its full name
                midi = _open(spec, api, f"{client}-{os.getpid()}" if spec != "virtual" and api == "UNIX_JACK"
                             else client)
            except NoPortYet as exc:
                if waiting is None:
                    waiting = exc.waiting
                else:
                    exc.waiting.close()
                reasons.append(f"{'JACK' if api == 'UNIX_JACK' else 'ALSA'}: {exc}")
                continue
            except (OSError, MidiUnavailable, ValueError, RuntimeError) as exc:
                reasons.append(f"{'JACK' if api == 'UNIX_JACK' else 'ALSA'}: {str(exc).strip() or type(exc).__name__}")
                continue
            except ImportError as exc:
                reasons.append(f"python-rtmidi missing ({exc})")
                break
        if waiting is not None:
            waiting.close()
        return midi
    if waiting is not None:
        say(f"MIDI: no controller yet ({'; '.join(reasons)}); plugging one in is picked up within {RESCAN:g} s, "
            "the on-screen knobs work meanwhile")
        return waiting
    say(f"MIDI: no input opened ({'; '.join(reasons)}); use the on-screen knobs")
    return None
