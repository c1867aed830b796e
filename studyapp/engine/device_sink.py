"""A PortAudio output device as a sink: a FIFO kept ``lead`` seconds ahead, read by the device's callback.

The device's callback is the audio clock (the sink is ``paced``). When the FIFO
cannot fill a device period the callback plays silence for the rest and counts
an *underrun*; when the device itself reports one (``output_underflow``, e.g.
a JACK xrun) that is counted too, and separately as an *xrun*. The session's
recorder is fed from the callback (``play``), with what it played: the file
is sample-aligned with what reached the device, a gap being silence there, and
its place marked in audio_cues.csv (engine/audio_recorder.py).
"""

import contextlib
import threading

import numpy as np

from studyapp.engine.audio import DEVICE_RATE, AudioUnavailable, Fifo, Sink, load_sounddevice
from studyapp.engine.native_stderr import captured_native_stderr


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
