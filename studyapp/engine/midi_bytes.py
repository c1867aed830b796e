"""Raw MIDI bytes to whole messages, resynchronising after anything malformed or unterminated.

A MIDI byte is a *status* byte (bit 7 set) or a *data* byte. Each message
starts with a status byte and holds a fixed number of data bytes (channel
messages: 1 for program change and channel pressure, 2 for the others), except
a System Exclusive, which runs from ``F0`` to ``F7``. MIDI 1.0 says a status
byte other than a real-time one (``F8``-``FF``, which may appear anywhere and
stand alone) ends a SysEx, terminated or not. ``split`` follows that: an
unterminated SysEx (``F0 7E 01``) is dropped at the next status byte, which
starts the next message; a channel message cut short by a status byte is
dropped; data bytes after a complete channel message start another of the
same status (running status); stray data bytes (no status before them) are
dropped.

Why it matters: rtmidi's JACK back-end appends every event after an
unterminated SysEx to that SysEx until an event ends in ``F7`` (RtMidi.cpp,
``continueSysex``). With SysEx ignored (its default, and ours on main) all of
them were thrown away: one ``F0 7E 01`` silenced MIDI for good (issue 33, item
4). The input now keeps SysEx, a lone ``F7`` is sent to our own port now and
then to end a SysEx left open (midi.py, ``FLUSH``), and what comes back, the
knob moves inside it included, is split here.
"""

SYSEX, EOX = 0xF0, 0xF7
REALTIME = 0xF8
_SYSTEM_LENGTHS = {0xF1: 2, 0xF2: 3, 0xF3: 2, 0xF6: 1}  # the system common messages, status included


def _length(status):
    """Bytes in the message that ``status`` starts (status included); None for SysEx and unknown ones."""
    if status < SYSEX:
        return 2 if status & 0xF0 in (0xC0, 0xD0) else 3
    return _SYSTEM_LENGTHS.get(status)


def split(data):
    """The whole messages (lists of bytes) in ``data``, in order; the rest dropped (module docstring)."""
    messages = []
    current = None  # the message being read, or None between messages
    running = None  # the last channel status: data bytes after its message start another (running status)
    for byte in data:
        if byte >= REALTIME:
            messages.append([byte])  # stands alone, even inside another message
            continue
        if byte & 0x80:  # a status byte ends what came before it, and starts a message
            if byte == EOX and current is not None and current[0] == SYSEX:
                messages.append(current + [EOX])
            length = None if byte == EOX else _length(byte)
            current = [byte] if byte == SYSEX or (length or 0) > 1 else None
            running = byte if byte < SYSEX else None
            if length == 1:
                messages.append([byte])
            continue
        if current is None and running is not None:
            current = [running]
        if current is None:
            continue  # a data byte with no status before it
        current.append(byte)
        if current[0] != SYSEX and len(current) == _length(current[0]):
            messages.append(current)
            current = None
    return messages
