"""The one exception of the device protocol's codec.

A ``ProtocolError`` is a frame or message that breaks the protocol (a CRC
that fails, malformed COBS, an unknown type, a body of the wrong length, a
value out of range). Its message names the field. Receivers count it
(``corrupt``) and never apply the frame; a host that refuses a handshake
shows it as one line.
"""


class ProtocolError(ValueError):
    """A frame or message that breaks the device protocol; the message names the field."""
