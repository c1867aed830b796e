"""Audio sinks for the string's sound: a PortAudio device, a WAV file, or nothing.

The closed loop renders audio at the haptic rate; a sink passes it through
the signal chain (``signal_chain.SignalChain``: the fixed stimulus gain,
silence while the bow is lifted and fades at every start, stop and cut, the
resampler to the sink's rate, the headphone check's reference tone, volume
and mute, and a soft limiter under ``CEILING_DBFS`` that counts what it bends), and plays or stores it. The session's
recorder (``recorder.AudioRecorder``), if one is attached, gets what reached
the device: a device sink tees it in its callback (``DeviceSink.play``), gaps
included (an underrun is silence in the file, and marked in audio_cues.csv),
a file sink as it writes. Choose one with
``open_sink(spec, haptic_rate)``::

    "device" | "device:NAME"   PortAudio output (sounddevice), NAME a substring of the device name
    "wav:FILE"                 16-bit mono WAV at 48 kHz (wav.py), written atomically when the sink closes;
                               never over an existing file: FILE taken, it is FILE-2, FILE-3, ... (a notice says which)
    "null"                     nothing rendered at all
    "discard"                  rendered and resampled, then dropped (what audio costs, for benchmarks)

A device sink (``DeviceSink``) plays from a FIFO (fifo.py) that the engine
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

import contextlib
import os
import tempfile
import threading

import numpy as np

from studyapp.io.atomic import default_mode, hold, remove_stale
from studyapp.engine.audio.fifo import Fifo
from studyapp.engine.audio.wav import open_wav, pcm16
from studyapp.engine.native_stderr import captured_native_stderr
from studyapp.engine.signal_chain import Gain, SignalChain
from studyapp.errors import ParameterError
from studyapp.io.free_names import claim, first_free, name_unnamed, unnamed

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

    @property
    def limited(self):
        """Output samples the limiter bent so far (signal_chain.py); none without a chain."""
        return self.chain.limited if self.chain else 0

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
    Until then the file has no name (``O_TMPFILE``), so a killed program leaves nothing behind;
    a named temporary ``.FILE.XXXXXXXX.wav`` that a killed run left (older versions, or a
    filesystem without ``O_TMPFILE``) is removed by the next sink of the same FILE.
    """

    render = True

    def __init__(self, path, haptic_rate, rate=WAV_RATE, say=print):
        super().__init__(haptic_rate, rate)
        self.say = say
        self.path = str(first_free(path))
        if self.path != str(path):
            say(f"audio: {path} exists; writing {self.path} (never over an earlier file)")
        self.rate = float(rate)
        folder = os.path.dirname(os.path.abspath(self.path))
        remove_stale(self.path)  # a named temporary an earlier, killed run left (before O_TMPFILE was used)
        fd = unnamed(folder, default_mode())  # no name until complete: a kill leaves nothing
        self._tmp = None
        if fd is None:  # a filesystem without O_TMPFILE: a named temporary, held so the next run removes it
            fd, self._tmp = tempfile.mkstemp(prefix=f".{os.path.basename(self.path)}.", suffix=".wav", dir=folder)
            os.fchmod(fd, default_mode())  # an output's usual permissions, not mkstemp's private ones
            hold(fd)
        self._file = open(fd, "w+b")  # noqa: SIM115 - closed in close()
        self._wav = open_wav(self._file, self.rate)
        self.frames = 0

    @property
    def description(self):
        return f"wav:{self.path} ({self.rate:g} Hz)"

    def _write(self, out):
        self._wav.writeframesraw(pcm16(out))
        self.frames += out.shape[0]

    def push(self, audio, sounding=True, cut=False):
        self._write(self._heard(audio, sounding, cut))

    def close(self):
        if self._wav is None:
            return
        self._write(self.chain.flush())
        self._wav.close()
        self._wav = None
        chosen = self.path
        if self._tmp is None:
            self._file.flush()
            self.path = str(name_unnamed(self._file.fileno(), self.path))
        else:
            self.path = str(_move_free(self._tmp, self.path))
        self._file.close()
        if self.path != chosen:
            self.say(f"audio: {chosen} appeared meanwhile; wrote {self.path} (never over an earlier file)")


def _move_free(source, path):
    """Move ``source`` to ``path`` or the first free numbered name after it; never replaces another's file.

    The name is reserved by an exclusive create, then ``source`` renamed over that empty file of ours.
    """
    fd, target = claim(path)
    os.close(fd)
    os.replace(source, target)
    return target


class DeviceSink(Sink):
    """A PortAudio output stream fed from a FIFO kept ``lead`` seconds ahead; paces the loop."""

    render = True
    paced = True

    def __init__(self, haptic_rate, device=None, rate=None, lead=0.03, channels=2):
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
        super().__init__(haptic_rate, self.rate)
        self.lead_frames = int(lead * self.rate)
        self.fifo = Fifo(max(4 * self.lead_frames, int(self.rate)))
        self.fifo_dropped = 0  # frames the FIFO had no room for (the device stopped calling back)
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
        outdata[:] = self.play(frames, status.output_underflow)[:, None]

    def play(self, frames, underflow=False):
        """The next device period: from the FIFO, silence for what it lacks; teed to the recorder as played."""
        if self._scratch.shape[0] != frames:
            self._scratch = np.zeros(frames, dtype=np.float32)
        start = self.fifo.read_position
        got = self.fifo.read_into(self._scratch)
        self.period_frames = max(self.period_frames, frames)
        short = got < frames
        if short:
            self._scratch[got:] = 0.0
            self.shortfalls += 1
        if underflow:
            self.xruns += 1
        if short or underflow:
            self.underruns += 1
        recorder = self.recorder
        if recorder is not None:
            # what reached the device, sample for sample: a gap is silence in the file, and marked
            recorder.write(self._scratch, start, got=got, underflow=bool(underflow))
        self.callbacks += 1
        self.frames_played += frames
        self._wanted.set()
        return self._scratch

    def push(self, audio, sounding=True, cut=False):
        # the whole chain before the FIFO: the FIFO holds what is heard
        out = self._heard(audio, sounding, cut).astype(np.float32)
        self.fifo_dropped += out.shape[0] - self.fifo.write(out)

    def next_frame(self):
        """The next block's first sample as a FIFO position (what the callback's recorder counts in)."""
        return self.chain.next_frame() - self.fifo_dropped

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
