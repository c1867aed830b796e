"""What a live session keeps beside its log: the audio heard, its cues, the level check's tone, trial health. No Qt.

Audio kept with the data. Each time a session's engine comes up
(``engine_up``) the session log gets an ``engine`` record and the engine is
asked to record what the participant hears into the session folder
(``RecordAudio``: audio.wav, then audio-2.wav, ... for a restarted engine or a
resumed session; the worker picks the free name); the recording stops when
the session ends. Each step's start (right after its knob mapping, so at the
same block boundary) and end is sent as an ``AudioCue``: the worker writes it
to audio_cues.csv at its own audio frame counter (engine/audio/recorder.py),
so no sample position crosses the process boundary.

The reference tone. A calibration page (the headphone level check) sends
``ReferenceTone(tone_hz, level_dbfs)`` when it starts and
``ReferenceTone(level_dbfs=None)`` when it ends (acknowledged, paused,
stopped, or the session ended).

Trial health. The engine's counters (``deadline_misses``, ``audio_underruns``,
``faults``, ``events_dropped``, ``audio_limited``) are read when a step starts and when it ends
(its response, the session's end, or its engine lost); their differences are
logged as a ``trial_health`` record (``underruns`` for the audio underruns,
``limited`` for the output samples the limiter bent),
which export carries as columns.
"""

from studyapp.engine import commands as cmd
from studyapp.experiment import records
from studyapp.experiment.data_modes import file_mode
from studyapp.experiment.trial_health import HEALTH

AUDIO_FILE = "audio.wav"  # what the participant heard, in the session folder (audio-2.wav, ... per engine run)


class TrialMedia:
    def __init__(self, live):
        self.live = live  # the controller: its apparatus, runner and session
        self._health = None  # the engine and its counters when the current step started
        self._tone = False  # a calibration page's reference tone is playing

    def engine_up(self):
        """A session's engine runs: log it, and record what the participant hears."""
        live = self.live
        live.runner.log(records.engine(live.host.engine.info, live.host.config.seed))
        # one file per engine run; participant data, with the mode of the session's other files
        live.apparatus.send(cmd.RecordAudio(str(live.session.folder / AUDIO_FILE), file_mode()))

    def stop_recording(self):
        self.live.apparatus.send(cmd.RecordAudio(None))

    def cue(self, event):
        """A row of the session's audio_cues.csv: the current step ``start``s or ``end``s."""
        runner = self.live.runner
        trial = runner.trial if runner is not None else None
        if trial is not None:
            self.live.apparatus.send(cmd.AudioCue(trial.step, trial.task, trial.trial, event))

    def reference_tone(self, on):
        """Start the current calibration page's reference tone (True), or end a playing one (False)."""
        runner = self.live.runner
        trial = runner.trial if runner is not None else None
        page = trial.page if trial is not None else None
        if on and page is not None and page.kind == "calibration" and not self._tone:
            self.live.apparatus.send(cmd.ReferenceTone(page.tone_hz, page.level_dbfs))
            self._tone = True
        elif not on and self._tone:
            self.live.apparatus.send(cmd.ReferenceTone(level_dbfs=None))
            self._tone = False

    def step_starts(self):
        """Read the engine's counters as a step starts (nothing without a running engine)."""
        engine = self.live.engine
        self._health = None if engine is None else (engine, self._counters(engine.status()))

    @staticmethod
    def _counters(status):
        return {key: int(status[key]) for key in HEALTH}

    def log_health(self):
        """The step ends: its audio cue, and its ``trial_health`` (its engine's counters now minus at its start)."""
        started, self._health = self._health, None
        runner = self.live.runner
        if started is None or runner is None or runner.trial is None:
            return
        self.cue("end")
        engine, before = started
        try:
            now = self._counters(engine.status())
        except (OSError, ValueError, KeyError):
            return  # the engine is gone with its status block: nothing to count
        counts = {HEALTH[key]: now[key] - before[key] for key in HEALTH}
        runner.log(records.trial_health(runner.trial.trial, **counts))
