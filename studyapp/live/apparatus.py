"""The live session's apparatus: one engine at a time, and the only way a command reaches its worker. No Qt.

``Apparatus`` holds the engine host (engine_host.py: started and stopped
without blocking) and makes each trial's ``EngineLoop`` (engine_loop.py: the
runner's loop, played by the engine). Every command the parent sends goes
through one of the two: ``send`` and the few named holds below (a page's
silence, the emergency stop's, the preview's mapping), or the trial's loop for
the settings a trial makes. Nothing else in studyapp.live calls
``engine.send``.

Engines. A protocol gets a *preview* engine with every condition it names
(``scene_conditions``) and the live mapping (``engine.commands.default_actions``:
knob 1 F_max on its logarithmic scale, knob 2 volume, pad i the i-th
condition). Starting a session starts a fresh engine seeded with the
session's seed and no mapping; once the session ends it stays on as the
preview's. The protocol's ``fmax_ceiling`` is the engine's hard clamp, in the
preview too.
"""

from studyapp.engine.load_margin import hang_timeout_for, load_per_core
from studyapp.engine import commands as cmd
from studyapp.engine.config import HANG_TIMEOUT, EngineConfig
from studyapp.engine.safety import SafetyLimits
from studyapp.experiment.tasks import task_type
from studyapp.live.engine_host import EngineHost
from studyapp.live.engine_loop import EngineLoop


def scene_conditions(protocol):
    """Every condition the protocol names, in the order it first names them."""
    names = []
    for task in protocol.tasks:
        for name in protocol.task(task).conditions:
            if name not in names:
                names.append(name)
    return names


def preview_actions(protocol):
    """The mapping outside a session: live use of every condition the protocol names."""
    return cmd.default_actions(scene_conditions(protocol))


def trial_actions(trial, task):
    """The knob mapping the worker applies during a trial: the task type's (``knob_actions``)."""
    return task_type(trial.task).knob_actions(trial, task)


class Apparatus:
    def __init__(self, audio="device", midi="first", device=None, realtime=True, hang_timeout=None,
                 make_host=EngineHost):
        self.audio = audio
        self.midi = midi
        self.device = device
        self.realtime = realtime
        self.hang_timeout = hang_timeout
        self.make_host = make_host
        self.device_options = {}  # EngineConfig's device_* fields for a link (device_latency, device_silence, ...)
        self.host = None
        self._seen = None  # the host's state the controller last followed

    @property
    def engine(self):
        """The running engine, or None (starting, failed or stopped)."""
        return self.host.engine if self.host is not None and self.host.running else None

    def config(self, protocol, seed, actions):
        """The engine for ``protocol``: every condition it names, seeded with ``seed``, silent, ``actions`` mapped."""
        names = scene_conditions(protocol)
        config = EngineConfig(rate=protocol.rate, estimators={n: protocol.estimator_params(n) for n in names},
                              source=names[0], fmax=0.0, gesture=protocol.gesture, bowing=False,
                              seed=int(seed) % 2**32, audio=self.audio, midi=self.midi, actions=actions,
                              realtime=self.realtime, device=self.device,
                              safety=SafetyLimits(fmax_ceiling=protocol.fmax_ceiling))
        if self.hang_timeout is not None:
            config.hang_timeout = float(self.hang_timeout)
        if self.device:
            for key, value in self.device_options.items():
                setattr(config, key, value)
        return config

    def replace(self, config, describe):
        """Start an engine with ``config``; the old one stops in the background.

        A device on a link takes one host at a time: the new engine opens it only once the old one has
        stopped (``EngineHost.start(after=...)``), still without blocking the caller."""
        if self.hang_timeout is None:  # the bound follows the machine's load at each start (engine/load_margin.py)
            config.hang_timeout = hang_timeout_for(load_per_core(), HANG_TIMEOUT)
        old = self.host
        stopping = old.stop(wait=False) if old is not None else None
        host = self.make_host(config, describe)
        self.host = host.start(after=stopping) if config.device and stopping is not None else host.start()
        self._seen = None  # announced, and followed, at the next poll

    def state_change(self):
        """The host's state if it changed since the last call (``starting``, ``running``, ...), else None."""
        state = self.host.state
        if state == self._seen:
            return None
        self._seen = state
        return state

    def send(self, *commands):
        """Send ``commands`` to the running engine's worker (nothing without one)."""
        engine = self.engine
        if engine is not None:
            for command in commands:
                engine.send(command)

    def loop(self, estimators, source, gesture, trial, actions, positions):
        """A trial's loop on the running engine (engine_loop.py): it sends the trial's settings."""
        return EngineLoop(self.host.engine, estimators, source, gesture, trial, actions, positions)

    # holds -----------------------------------------------------------------------------------------
    def hold_page(self, trial):
        """A page: F_max 0, the bow lifted, no knob acting, controls tagged with the page's ``trial``."""
        self.send(cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions({}, trial=trial))

    def tag(self, trial):
        """Controls tagged ``trial`` with no knob acting (a held page: ``-trial``)."""
        self.send(cmd.InstallActions({}, trial=trial))

    def silence(self):
        """F_max 0, the bow lifted, no knob mapping (an emergency stop without a trial's loop)."""
        self.send(cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions({}))

    def map_preview(self, protocol):
        self.send(cmd.InstallActions(preview_actions(protocol)))

    def to_preview(self, protocol):
        """A session ended: the engine silent, then the preview's mapping."""
        self.send(cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions(preview_actions(protocol)))

    # the force word in shared memory (not a command: it acts at the worker's next block) -----------
    def disable_force(self, reason):
        engine = self.engine
        if engine is not None:
            engine.status_block.disable_force(reason)

    def enable_force(self):
        """Unlatch a stop; False without a running engine (nothing to clear)."""
        engine = self.engine
        if engine is None:
            return False
        engine.status_block.force_enable = True
        engine.clear_fault()
        return True

    def stop(self):
        """Stop the engine (waits for it)."""
        if self.host is not None:
            self.host.stop(wait=True)
            self.host = None
