"""What the engine runs: the scene's loop settings plus block size, sinks, MIDI and safety.

``EngineConfig`` crosses the process boundary (pickled for the spawn-context
worker), so it holds only plain values; a real device driver is named as
``"module:factory"`` and the factory is called with the rate in the worker.
"""

from dataclasses import dataclass, field

from studyapp.engine.safety import SafetyLimits
from studyapp.errors import ParameterError
from studyapp.model.sources import LVT_SENSOR, with_pseudo_sources

BLOCK_PERIOD = 0.002  # s: default block length; commands and MIDI act at block boundaries


def block_samples(rate, period=BLOCK_PERIOD):
    """Samples in a block of ``period`` seconds at ``rate`` (at least one)."""
    return max(1, int(round(rate * period)))


@dataclass
class EngineConfig:
    rate: float = 5000.0  # haptic rate, Hz
    estimators: dict = field(default_factory=dict)  # active set: name -> params ({} = Table 1 defaults)
    source: str = LVT_SENSOR  # an active estimator or a pseudo-source (model/sources.py)
    fmax: float = 1.0  # N
    gesture: str = "strokes"
    f0: float | None = None  # Hz; None: the model's default
    seed: int = 0
    block: int | None = None  # samples per block; None: BLOCK_PERIOD worth
    audio: str = "null"  # device | device:NAME | wav:FILE | null  (audio.parse)
    lead: float = 0.03  # s of audio queued ahead of a device
    midi: str = "none"  # PORT | first | virtual | none  (midi.open_input)
    midi_map: dict | None = None  # protocol's map (midi.ControlMap.from_protocol); None: LPD8 factory
    actions: dict | None = None  # control -> action (commands.action_commands); None: default_actions
    safety: SafetyLimits = field(default_factory=SafetyLimits)
    telemetry_seconds: float = 4.0  # history kept in the rings
    realtime: bool = True  # ask for SCHED_FIFO for the worker's loop thread (falls back silently)
    device: str | None = None  # "module:factory" of a real device driver; None: the simulated device
    hang_timeout: float = 0.08  # s without a heartbeat before the force guard calls the worker hung
    # s without the force guard's heartbeat before the worker switches its own force off: the guard's
    # failure is the rarer one, so the deadline is looser than hang_timeout, sparing a loaded machine false trips
    guard_timeout: float = 0.2

    def block_size(self):
        if self.block is not None:
            if int(self.block) < 1:
                raise ParameterError(f"block = {self.block}: allowed is a number of samples >= 1")
            return int(self.block)
        return block_samples(self.rate)

    def sources(self):
        """The velocity sources a pad can select, in the scene's order."""
        names = list(self.estimators) if isinstance(self.estimators, dict) else list(self.estimators)
        return with_pseudo_sources(names)
