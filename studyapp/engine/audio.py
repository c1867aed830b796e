"""Audio sinks for the string's sound: a PortAudio device, a WAV file, or nothing.

The closed loop renders audio at the haptic rate; a sink passes it through
the signal chain (``signal_chain.SignalChain``: silence while the bow is
lifted and fades at every start, stop and cut, the resampler to the sink's
rate, volume and mute, the headphone check's reference tone, and a soft
limiter under ``CEILING_DBFS``), and plays or stores it. The session's
recorder (``audio_recorder``), if one is attached, gets what reached the
device: a device sink tees it in its callback, gaps included (an underrun is
silence in the file, and marked), a file sink as it writes. Choose one with
``open_sink(spec, haptic_rate)``::

    "device" | "device:NAME"   PortAudio output (sounddevice), NAME a substring of the device name
    "wav:FILE"                 16-bit mono WAV at 48 kHz, written atomically when the sink closes; never
                               over an existing file: FILE taken, it is FILE-2, FILE-3, ... (a notice says which)
    "null"                     nothing rendered at all
    "discard"                  rendered and resampled, then dropped (what audio costs, for benchmarks)

A device sink (``device_sink.DeviceSink``) plays from a FIFO that the engine
keeps filled ``lead`` seconds ahead; PortAudio's callback reads it. When the FIFO cannot fill a device
period the callback plays silence for the rest and counts an *underrun*; when
the device itself reports one (``output_underflow``, e.g. a JACK xrun) that is
counted too, and separately as an *xrun*. The device's callback is the audio
clock: a device sink is ``paced``, and the engine waits on it instead of on a
timer. Without PortAudio, or without an output device, ``open_sink`` prints one
line and returns a null sink instead: the loop keeps running, silent.

Caveat (after python-sounddevice): PortAudio calls back from its own thread,
which must take the GIL to run; the worker lowers Python's switch interval so
that thread waits at most about half a millisecond.
"""

import os
import tempfile
import wave

import numpy as np

from studyapp.engine.audio_recorder import numbered
from studyapp.engine.native_stderr import captured_native_stderr
from studyapp.engine.signal_chain import Gain, SignalChain
from studyapp.errors import ParameterError

DEVICE_RATE = 48_000.0
WAV_RATE = 48_000.0


class AudioUnavailable(RuntimeError):
    """No PortAudio library, no output device, or the device refused the stream."""


def parse(spec):
    """``(kind, argument)`` of a sink spec; raises ``ParameterError`` naming ``--audio``."""
    spec = (spec or "null").strip()
    if spec in ("null", "discard"):
        return spec, None
    if spec == "device":
        return "device", None
    if spec.startswith("device:") and len(spec) > 7:
        return "device", spec[7:]
    if spec.startswith("wav:") and len(spec) > 4:
        path = spec[4:]
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):
            raise ParameterError(f"--audio {spec}: folder {folder} does not exist")
        try:  # a real write, removed at once: os.access says yes to root on /sys and /proc
            tempfile.TemporaryFile(dir=folder).close()
        except OSError as exc:
            raise ParameterError(f"--audio {spec}: folder {folder} is not writable ({exc.strerror or exc}): "
                                 "allowed is a WAV file in a writable folder") from None
        return "wav", path
    raise ParameterError(f"--audio {spec!r}: use device, device:NAME, wav:FILE, null or discard")


def load_sounddevice():
    """Import sounddevice (initialising PortAudio) quietly; ``AudioUnavailable`` with one line if absent."""
    with captured_native_stderr():
        try:
            import sounddevice
        except OSError as exc:
            raise AudioUnavailable(f"PortAudio not found ({exc}); install libportaudio2") from None
    return sounddevice


class Fifo:
    """Single-producer, single-consumer float32 FIFO between the engine thread and the audio callback.

    Each side moves only its own counter, after touching the data, and a
    Python int assignment is atomic under the GIL, so no lock is needed.
    """

    def __init__(self, capacity):
        self.capacity = int(capacity)
        self._data = np.zeros(self.capacity, dtype=np.float32)
        self._written = 0
        self._read = 0

    @property
    def level(self):
        return self._written - self._read

    @property
    def read_position(self):
        """Frames read so far: the position in the written stream of the next frame read."""
        return self._read

    def write(self, samples):
        n = min(samples.shape[0], self.capacity - self.level)
        start = self._written % self.capacity
        split = min(n, self.capacity - start)
        self._data[start:start + split] = samples[:split]
        self._data[:n - split] = samples[split:n]
        self._written += n
        return n

    def read_into(self, out):
        n = min(out.shape[0], self.level)
        start = self._read % self.capacity
        split = min(n, self.capacity - start)
        out[:split] = self._data[start:start + split]
        out[split:n] = self._data[:n - split]
        self._read += n
        return n


class Sink:
    """What the engine needs of any sink; this base one is the null sink."""

    render = False  # does the loop need to render audio for this sink?
    paced = False  # does the sink's clock pace the loop?
    rate = DEVICE_RATE

    def __init__(self, haptic_rate=None, rate=None):
        # a sink that renders has the signal chain at its own rate; the null sink keeps only a volume
        self.chain = SignalChain(haptic_rate, rate) if self.render else None
        self.gain = self.chain.gain if self.chain else Gain()
        self.tone = self.chain.tone if self.chain else None
        self.recorder = None  # the session's AudioRecorder, fed what this sink outputs
        self.underruns = 0  # device periods played with a gap, for whatever reason
        self.shortfalls = 0  # ... because the FIFO ran dry (the engine was late)
        self.xruns = 0  # ... because the device reported an underflow
        self.frames_played = 0

    @property
    def description(self):
        return "null"

    def start(self):
        pass

    def push(self, audio, sounding=True, cut=False):
        """Take one block of the loop's audio (at the haptic rate): ``sounding`` False while the bow is
        lifted, ``cut`` True when the model's sound jumps at this block (a reset, a new source)."""

    def next_frame(self):
        """The frame of the sink's output stream at which the next block's first sample is heard."""
        return self.chain.next_frame() if self.chain else 0

    def wait(self, timeout):
        """Block until the sink wants more audio (paced sinks; ``False`` on timeout); return at once otherwise."""
        return True

    def set_volume(self, volume):
        self.gain.set_volume(volume)

    def set_mute(self, muted):
        self.gain.muted = bool(muted)
        if self.tone is not None:
            self.tone.set_muted(muted)

    def set_reference_tone(self, hz, level_dbfs):
        if self.tone is None:
            raise ParameterError(f"reference tone: the {self.description} sink plays no sound")
        self.tone.set(hz, level_dbfs)

    def _heard(self, audio, sounding, cut):
        """What the listener hears of one block; a file sink tees it to the recorder (a device, in its callback)."""
        start = self.chain.emitted
        out = self.chain.process(audio, sounding, cut)
        if self.recorder is not None and not self.paced:
            self.recorder.write(out, start)
        return out

    def close(self):
        pass


class DiscardSink(Sink):
    """Renders and resamples, then drops: the cost of audio without a device (benchmarks)."""

    render = True

    def __init__(self, haptic_rate, rate=DEVICE_RATE):
        super().__init__(haptic_rate, rate)
        self.rate = float(rate)

    @property
    def description(self):
        return f"discard ({self.rate:g} Hz)"

    def push(self, audio, sounding=True, cut=False):
        self._heard(audio, sounding, cut)


class WavSink(Sink):
    """A 16-bit mono WAV file, complete or absent: it appears under its name only on ``close``.

    Never over an existing file: the name is the first free one of FILE, FILE-2, ... when the
    sink opens (``say`` tells which, if not FILE) and again when it closes, reserved by an
    exclusive create (two engines writing the same FILE at once both keep their take).
    """

    render = True

    def __init__(self, path, haptic_rate, rate=WAV_RATE, say=print):
        super().__init__(haptic_rate, rate)
        self.say = say
        self.path = str(_free_name(path))
        if self.path != str(path):
            say(f"audio: {path} exists; writing {self.path} (never over an earlier file)")
        self.rate = float(rate)
        folder, name = os.path.split(os.path.abspath(self.path))
        fd, self._tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".wav", dir=folder)
        os.fchmod(fd, 0o666 & ~_umask())  # an output's usual permissions, not mkstemp's private ones
        os.close(fd)
        self._wav = wave.open(str(self._tmp), "wb")
        self._wav.setnchannels(1)
        self._wav.setsampwidth(2)
        self._wav.setframerate(int(round(self.rate)))
        self.frames = 0

    @property
    def description(self):
        return f"wav:{self.path} ({self.rate:g} Hz)"

    def _write(self, out):
        pcm = np.round(out * 32767.0).astype("<i2")
        self._wav.writeframesraw(pcm.tobytes())
        self.frames += pcm.shape[0]

    def push(self, audio, sounding=True, cut=False):
        self._write(self._heard(audio, sounding, cut))

    def close(self):
        if self._wav is None:
            return
        self._write(self.chain.flush())
        self._wav.close()
        self._wav = None
        chosen = self.path
        self.path = str(_move_free(self._tmp, self.path))
        if self.path != chosen:
            self.say(f"audio: {chosen} appeared meanwhile; wrote {self.path} (never over an earlier file)")


def _umask():
    umask = os.umask(0)
    os.umask(umask)
    return umask


def _free_name(path):
    """``path``, or the first of ``path-2``, ``path-3``, ... that does not exist."""
    number = 1
    while os.path.lexists(numbered(path, number)):
        number += 1
    return numbered(path, number)


def _move_free(source, path):
    """Move ``source`` to ``path`` or the first free numbered name after it; never replaces another's file.

    The name is reserved by an exclusive create, then ``source`` renamed over that empty file of ours.
    """
    number = 1
    while True:
        target = numbered(path, number)
        try:
            os.close(os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
        except FileExistsError:
            number += 1
            continue
        os.replace(source, target)
        return target


def open_sink(spec, haptic_rate, say=print, lead=0.03):
    """The sink named by ``spec`` (see module docstring); a null sink, and one line, if a device is unusable."""
    kind, arg = parse(spec)
    if kind == "null":
        return Sink()
    if kind == "discard":
        return DiscardSink(haptic_rate)
    if kind == "wav":
        return WavSink(arg, haptic_rate, say=say)
    from studyapp.engine.device_sink import DeviceSink

    try:
        return DeviceSink(haptic_rate, device=arg, lead=lead)
    except AudioUnavailable as exc:
        say(f"audio: {exc}; continuing without sound (null sink)")
        return Sink()
