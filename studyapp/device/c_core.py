"""The C core (firmware/studyapp_device.c), built with the system's C compiler and loaded with ctypes."""


class BuildError(RuntimeError):
    """The C core could not be built or loaded (one line)."""


class CCore:
    def __init__(self, info):
        raise BuildError("not built yet")
