"""CRC-16/CCITT-FALSE, the frames' check (docs/device-protocol.md, Framing).

Polynomial x^16 + x^12 + x^5 + 1 (0x1021), initial value 0xFFFF, input and
output not reflected, no final xor; the catalogue's check value of
b"123456789" is 0x29B1. Every single-bit error and every burst of up to 16
bits is detected. Table-driven, one byte at a time, as a firmware does it
(firmware/studyapp_device_link.c computes the same CRC bit by bit).
"""

POLY = 0x1021
INIT = 0xFFFF


def _table():
    table = []
    for byte in range(256):
        c = byte << 8
        for _ in range(8):
            c = ((c << 1) ^ POLY) if c & 0x8000 else (c << 1)
        table.append(c & 0xFFFF)
    return tuple(table)


TABLE = _table()


def crc16(data, crc=INIT):
    """The CRC of ``data`` (bytes-like), continuing from ``crc``."""
    for b in data:
        crc = ((crc << 8) & 0xFFFF) ^ TABLE[(crc >> 8) ^ b]
    return crc
