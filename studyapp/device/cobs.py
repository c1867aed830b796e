"""Consistent Overhead Byte Stuffing (Cheshire & Baker, IEEE/ACM Trans. Networking 7(2), 1999).

COBS rewrites a byte string so that it holds no 0x00, which then delimits
frames on the wire. The output is a sequence of blocks: a code byte n
(1..255) followed by n - 1 non-zero bytes; a code below 255 stands for its
n - 1 bytes and a 0x00 after them, except at the very end. The overhead is
at most one byte per 254 bytes plus one.
"""

from studyapp.device.errors import ProtocolError


def encode(data):
    """``data`` stuffed: no 0x00 in the result (a full block of 254 at the very end gets no empty block after it)."""
    out = bytearray()
    block = bytearray()
    for b in data:
        if len(block) == 254:
            out.append(255)
            out += block
            block.clear()
        if b == 0:
            out.append(len(block) + 1)
            out += block
            block.clear()
        else:
            block.append(b)
    out.append(255 if len(block) == 254 else len(block) + 1)
    out += block
    return bytes(out)


def decode(data):
    """The bytes ``encode`` was given; ``ProtocolError`` for a 0x00 inside or a block that runs past the end."""
    out = bytearray()
    i = 0
    n = len(data)
    while i < n:
        code = data[i]
        if code == 0:
            raise ProtocolError(f"COBS: a zero byte at offset {i}")
        end = i + code
        if end > n:
            raise ProtocolError(f"COBS: the block at offset {i} runs past the end")
        block = data[i + 1:end]
        if 0 in block:
            raise ProtocolError(f"COBS: a zero byte inside the block at offset {i}")
        out += block
        i = end
        if code < 255 and i < n:
            out.append(0)
    return bytes(out)
