"""Audio sinks for the string's sound: a PortAudio device, a WAV file, or nothing.

The closed loop renders audio at the haptic rate; a sink resamples it to its
own rate (``resampler.Resampler``), applies volume and mute, puts in the
headphone check's reference tone when it is on (``reference_tone``: it
replaces the string's sound and does not pass through the volume knob), tees
the result to the session's recorder if one is attached (``audio_recorder``),
and plays or stores it. Choose one with ``open_sink(spec, haptic_rate)``::

    "device" | "device:NAME"   PortAudio output (sounddevice), NAME a substring of the device name
    "wav:FILE"                 16-bit mono WAV at 48 kHz, written atomically when the sink closes; never
                               over an existing file: FILE taken, it is FILE-2, FILE-3, ... (a notice says which)
    "null"                     nothing rendered at all
    "discard"                  rendered and resampled, then dropped (what audio costs, for benchmarks)

A device sink plays from a FIFO that the engine keeps filled ``lead`` seconds
ahead; PortAudio's callback reads it. When the FIFO cannot fill a device
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

import contextlib
import os
import tempfile
import tempfile
import threading
import wave

import numpy as np

from studyapp.engine.audio_recorder import numbered
from studyapp.engine.native_stderr import captured_native_stderr
from studyapp.engine.reference_tone import ReferenceTone
from studyapp.engine.resampler import Resampler
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


class Gain:
    """Volume and mute, ramped linearly over one block on every change so changes never click.

    Settings made before the first block apply at once (there is nothing to click against).
    """

    def __init__(self, volume=1.0):
        self.volume = float(volume)
        self.muted = False
        self._now = None

    @property
    def target(self):
        return 0.0 if self.muted else self.volume

    def apply(self, block):
        target = self.target
        if self._now is None:
            self._now = target
        if target == self._now:
            block *= target
        else:
            block *= np.linspace(self._now, target, block.shape[0] + 1)[1:]
            self._now = target
        np.clip(block, -1.0, 1.0, out=block)
        return block


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

    def __init__(self):
        self.gain = Gain()
        self.tone = None  # a sink that renders makes its ReferenceTone at its own rate
        self.recorder = None  # the session's AudioRecorder, fed every block this sink outputs
        self.underruns = 0  # device periods played with a gap, for whatever reason
        self.shortfalls = 0  # ... because the FIFO ran dry (the engine was late)
        self.xruns = 0  # ... because the device reported an underflow
        self.frames_played = 0

    @property
    def description(self):
        return "null"

    def start(self):
        pass

    def push(self, audio):
        """Take one block of the loop's audio (at the haptic rate)."""

    def wait(self, timeout):
        """Block until the sink wants more audio (paced sinks; ``False`` on timeout); return at once otherwise."""
        return True

    def set_volume(self, volume):
        if not 0.0 <= volume <= 4.0:
            raise ParameterError(f"volume: {volume} is outside 0..4")
        self.gain.volume = float(volume)

    def set_mute(self, muted):
        self.gain.muted = bool(muted)
        if self.tone is not None:
            self.tone.set_muted(muted)

    def set_reference_tone(self, hz, level_dbfs):
        if self.tone is None:
            raise ParameterError(f"reference tone: the {self.description} sink plays no sound")
        self.tone.set(hz, level_dbfs)

    def _heard(self, samples):
        """What the listener hears of resampled ``samples``: volume and mute, the tone; teed to the recorder."""
        out = self.tone.mix(self.gain.apply(samples))
        if self.recorder is not None:
            self.recorder.write(out)
        return out

    def close(self):
        pass


class DiscardSink(Sink):
    """Renders and resamples, then drops: the cost of audio without a device (benchmarks)."""

    render = True

    def __init__(self, haptic_rate, rate=DEVICE_RATE):
        super().__init__()
        self.rate = float(rate)
        self.resampler = Resampler(haptic_rate, self.rate)
        self.tone = ReferenceTone(self.rate)

    @property
    def description(self):
        return f"discard ({self.rate:g} Hz)"

    def push(self, audio):
        self._heard(self.resampler.process(audio))


class WavSink(Sink):
    """A 16-bit mono WAV file, complete or absent: it appears under its name only on ``close``.

    Never over an existing file: the name is the first free one of FILE, FILE-2, ... when the
    sink opens (``say`` tells which, if not FILE) and again when it closes, reserved by an
    exclusive create (two engines writing the same FILE at once both keep their take).
    """

    render = True

    def __init__(self, path, haptic_rate, rate=WAV_RATE, say=print):
        super().__init__()
        self.say = say
        self.path = str(_free_name(path))
        if self.path != str(path):
            say(f"audio: {path} exists; writing {self.path} (never over an earlier file)")
        self.rate = float(rate)
        self.resampler = Resampler(haptic_rate, self.rate)
        self.tone = ReferenceTone(self.rate)
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

    def _write(self, samples):
        pcm = np.round(self._heard(samples) * 32767.0).astype("<i2")
        self._wav.writeframesraw(pcm.tobytes())
        self.frames += pcm.shape[0]

    def push(self, audio):
        self._write(self.resampler.process(audio))

    def close(self):
        if self._wav is None:
            return
        self._write(self.resampler.flush())
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


class DeviceSink(Sink):
    """A PortAudio output stream fed from a FIFO kept ``lead`` seconds ahead; paces the loop."""

    render = True
    paced = True

    def __init__(self, haptic_rate, device=None, rate=None, lead=0.03, channels=2):
        super().__init__()
        sd = load_sounddevice()
        self._sd = sd
        try:
            with captured_native_stderr() as chatter:
                index = self._find(sd, device)
                info = sd.query_devices(index)
                self.rate = float(rate or info["default_samplerate"] or DEVICE_RATE)
                channels = max(1, min(channels, int(info["max_output_channels"])))
                self._stream = sd.OutputStream(
                    device=index, samplerate=self.rate, channels=channels, dtype="float32",
                    callback=self._callback, latency="low",
                )
        except (sd.PortAudioError, ValueError) as exc:
            detail = str(exc).strip().splitlines()[0] if str(exc).strip() else "no detail"
            hint = chatter.text.strip().splitlines()
            raise AudioUnavailable(f"no usable output device ({detail}{'; ' + hint[0] if hint else ''})") from None
        self.name = info["name"]
        self.hostapi = sd.query_hostapis(info["hostapi"])["name"]
        self.resampler = Resampler(haptic_rate, self.rate)
        self.tone = ReferenceTone(self.rate)
        self.lead_frames = int(lead * self.rate)
        self.fifo = Fifo(max(4 * self.lead_frames, int(self.rate)))
        self._wanted = threading.Event()
        self._scratch = np.zeros(0, dtype=np.float32)
        self.stuck = False
        self.period_frames = 0
        self.callbacks = 0

    @staticmethod
    def _find(sd, device):
        outputs = [d for d in sd.query_devices() if d["max_output_channels"] > 0]
        if not outputs:
            raise sd.PortAudioError("PortAudio sees no output device")
        if device is None:
            default = sd.default.device[1]
            return default if default is not None and default >= 0 else outputs[0]["index"]
        for d in outputs:
            if device.lower() in d["name"].lower():
                return d["index"]
        names = ", ".join(d["name"] for d in outputs)
        raise sd.PortAudioError(f"no output device matches {device!r} (have: {names})")

    @property
    def description(self):
        return f"{self.name} via {self.hostapi} ({self.rate:g} Hz, lead {1e3 * self.lead_frames / self.rate:.0f} ms)"

    @property
    def level(self):
        """Frames queued ahead of the device."""
        return self.fifo.level

    def _callback(self, outdata, frames, time_info, status):
        if self._scratch.shape[0] != frames:
            self._scratch = np.zeros(frames, dtype=np.float32)
        got = self.fifo.read_into(self._scratch)
        self.period_frames = max(self.period_frames, frames)
        short = got < frames
        if short:
            self._scratch[got:] = 0.0
            self.shortfalls += 1
        if status.output_underflow:
            self.xruns += 1
        if short or status.output_underflow:
            self.underruns += 1
        outdata[:] = self._scratch[:, None]
        self.callbacks += 1
        self.frames_played += frames
        self._wanted.set()

    def push(self, audio):
        # volume, mute and tone before the FIFO: the FIFO holds what is heard, as the recorder gets it
        self.fifo.write(self._heard(self.resampler.process(audio)).astype(np.float32))

    @property
    def target(self):
        """Frames to keep queued: the lead, and at least two device periods."""
        return max(self.lead_frames, 2 * self.period_frames)

    def wait(self, timeout):
        while self.fifo.level >= self.target:
            self._wanted.clear()
            if self.fifo.level < self.target:
                break
            if not self._wanted.wait(timeout):
                return False
        return True

    def start(self):
        """Start the stream; call once the FIFO holds ``lead`` (the engine primes it)."""
        self._stream.start()

    def close(self, timeout=2.0):
        """Abort and close the stream; ``False`` if PortAudio did not let go within ``timeout``.

        PortAudio's JACK back-end waits up to ten minutes for its callback to
        acknowledge a stop; a server that has dropped the client (after a long
        stall) never runs that callback again. So the stream is closed on a
        helper thread, and a sink that stays stuck is left behind
        (``self.stuck``): the worker then exits without terminating PortAudio.
        """
        if self._stream is None:
            return not self.stuck
        stream, self._stream = self._stream, None
        done = threading.Event()

        def shut():
            with contextlib.suppress(self._sd.PortAudioError):
                stream.abort()
                stream.close()
            done.set()

        threading.Thread(target=shut, name="studyapp-audio-close", daemon=True).start()
        self.stuck = not done.wait(timeout)
        return not self.stuck


def open_sink(spec, haptic_rate, say=print, lead=0.03):
    """The sink named by ``spec`` (see module docstring); a null sink, and one line, if a device is unusable."""
    kind, arg = parse(spec)
    if kind == "null":
        return Sink()
    if kind == "discard":
        return DiscardSink(haptic_rate)
    if kind == "wav":
        return WavSink(arg, haptic_rate, say=say)
    try:
        return DeviceSink(haptic_rate, device=arg, lead=lead)
    except AudioUnavailable as exc:
        say(f"audio: {exc}; continuing without sound (null sink)")
        return Sink()
