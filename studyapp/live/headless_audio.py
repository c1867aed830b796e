"""A headless session's audio, archived as a live session's is: audio.wav and audio_cues.csv in its folder.

``studyapp run ... --simulated-participant --headless --audio wav`` runs the
closed loop in-process (``SessionRunner``), with no device and not in real
time. ``ArchivingRunner`` is that runner with the loop's audio rendered and
passed, block by block, through the live engine's signal chain
(engine/signal_chain.py: the stimulus gain, silence while the bow is lifted,
fades at every start, stop and cut, the resampler, the level check's
reference tone, the volume, the limiter) into the live engine's recorder (engine/audio/recorder.py). So
the file holds what a participant would have heard, and the checks made on
it hold for a live session too.

As in the live engine: each step's start and end is a cue (the start at the
frame where its first sample is heard), and so is each ``bow_on`` and
``bow_off``; a trial's start is a cut (a new loop
is a string at rest), and so is a change of velocity source; a page has no
loop: its time is silence, or the reference tone on a calibration page. The
simulated experimenter listens to the tone before confirming the level
(``PageType.simulate``), so the tone is in the file.
"""

from studyapp.engine.audio.recorder import AudioRecorder
from studyapp.engine.audio.sinks import WAV_RATE
from studyapp.engine.signal_chain import SignalChain
from studyapp.experiment.data_modes import file_mode
from studyapp.experiment.session_runner import SessionRunner, closed_loop_factory

AUDIO_FILE = "audio.wav"


class ArchivingRunner(SessionRunner):
    def __init__(self, session, progress=None):
        super().__init__(session, make_loop=closed_loop_factory(session.protocol, audio=True), progress=progress,
                         simulated=True)  # headless, only the simulated participant plays
        self.chain = SignalChain(self.protocol.rate, WAV_RATE)
        self.recorder = AudioRecorder(session.folder / AUDIO_FILE, self.chain.rate, file_mode())
        self.path = self.recorder.path  # audio.wav, or audio-2.wav, ... for a resumed session
        self._cut = False
        self._source = None

    def log(self, event):
        """Log ``event``; a response only once the recording and the cues up to it are on disk (a kill
        never leaves an answered step without its ``start`` row in audio_cues.csv)."""
        if event.get("type") == "response" and self.recorder is not None:
            self.recorder.sync()
        return super().log(event)

    def _cue(self, event):
        t = self.trial
        self.recorder.cue(t.step, t.task, t.trial, event, at=self.chain.next_frame())

    def _play(self, make):
        start = self.chain.emitted
        self.recorder.write(make(), start)

    def start_trial(self):
        if self.trial is not None:
            self._cue("end")
        self.chain.tone.set(self.chain.tone.hz, None)
        upcoming = self.session.next_trial()
        if upcoming is not None:  # cued first: a bow put on at the start belongs to this step
            self.recorder.cue(upcoming.step, upcoming.task, upcoming.trial, "start", at=self.chain.next_frame())
        trial = super().start_trial()
        if trial is None:
            return None
        self._cut = True
        page = trial.page
        if page is not None and page.kind == "calibration":
            self.chain.tone.set(page.tone_hz, page.level_dbfs)
        return trial

    def set_bowing(self, on):
        if self.loop is not None and bool(on) != self.bowing:
            self.recorder.cue(None, None, None, "bow_on" if on else "bow_off", at=self.chain.next_frame())
        super().set_bowing(on)

    def advance(self, seconds):
        if self.loop is None:
            self._play(lambda: self.chain.silence(max(1, int(round(seconds * self.protocol.rate)))))
            return super().advance(seconds)
        sounding = self.loop.bowing and self.loop.fault is None  # as the run starts, like the worker's block
        cut = self._cut or self.loop.source != self._source
        self._cut, self._source = False, self.loop.source
        block = super().advance(seconds)
        self._play(lambda: self.chain.process(block["audio"], sounding, cut))
        return block

    def finish(self, reason="done"):
        if self.trial is not None:
            self._cue("end")
        complete = super().finish(reason)
        self.close()
        return complete

    def close(self):
        """Play out the chain's tail and close the file (once)."""
        if self.recorder is None:
            return
        self._play(self.chain.flush)
        self.recorder.stop()
        self.recorder.join()
        if self.recorder.error:
            self.progress(f"warning: audio: recording stopped: {self.recorder.error}")
        self.recorder = None
