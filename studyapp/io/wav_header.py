"""A WAV file's header made true to the file's size again, after a kill.

The recorder (engine/audio/recorder.py, through the stdlib ``wave``) appends
its samples, then patches the header's two sizes: the RIFF chunk's (the file's
size less 8 bytes) and the ``data`` chunk's (the samples' bytes). A kill
between the two leaves a header that counts fewer samples than the file holds
(issue 41, item 15: 369,452 bytes with a header for 350,252); readers then
stop early, and the last part of what the participant heard is lost to them.

``repair_wav`` reads the chunks (``RIFF`` size ``WAVE``, then id, size,
body..., the ``data`` chunk last, as the recorder writes it), and when the
``data`` chunk's size is not what lies after it,

    data bytes = (file size - data offset) rounded down to whole frames (block align)
    RIFF size  = data offset + data bytes - 8

truncates a torn last frame and writes the two sizes. A file that is not
such a WAV (no RIFF/WAVE, no PCM ``fmt `` before ``data``), a link, or not
a regular file with one name is left as it is.
"""

import os
import stat
import struct

HEADER_LIMIT = 4096  # bytes: the recorder's header is 44; chunks before "data" are small


def _data_chunk(head):
    """(block align, offset of the data chunk's size field, offset of its samples), or None."""
    if len(head) < 12 or head[:4] != b"RIFF" or head[8:12] != b"WAVE":
        return None
    position, align = 12, None
    while position + 8 <= len(head):
        kind, size = head[position:position + 4], struct.unpack("<I", head[position + 4:position + 8])[0]
        if kind == b"fmt ":
            if size < 16 or position + 24 > len(head):
                return None
            tag, _, _, _, align = struct.unpack("<HHIIH", head[position + 8:position + 22])
            if tag != 1 or align == 0:  # PCM only, as the recorder writes
                return None
        elif kind == b"data":
            return (align, position + 4, position + 8) if align else None
        position += 8 + size + (size & 1)
    return None


def repair_wav(path):
    """Make the header of the WAV file ``path`` match its size; returns one line saying what was
    repaired, or None when it was right (or the file is not such a WAV, module docstring)."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError:
        return None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_nlink != 1:
            return None
        found = _data_chunk(os.pread(fd, HEADER_LIMIT, 0))
        if found is None:
            return None
        align, size_at, start = found
        head = os.pread(fd, 8, size_at - 4)
        stated = struct.unpack("<I", head[4:8])[0]
        data = max(info.st_size - start, 0) // align * align
        riff = struct.unpack("<I", os.pread(fd, 4, 4))[0]
        if stated == data and riff == start + data - 8 and info.st_size == start + data:
            return None
        if info.st_size > start + data:
            os.ftruncate(fd, start + data)  # a torn last frame
        os.pwrite(fd, struct.pack("<I", start + data - 8), 4)
        os.pwrite(fd, struct.pack("<I", data), size_at)
        os.fsync(fd)
    except OSError:
        return None
    finally:
        os.close(fd)
    return (f"{path}: its header counted {stated // align} frames, the file holds {data // align} (a kill between "
            "the recorder's write and its header's update): header repaired")
