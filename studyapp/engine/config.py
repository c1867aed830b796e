"""What the engine runs: the scene's loop settings plus block size, sinks, MIDI and safety.

``EngineConfig`` crosses the process boundary (pickled for the spawn-context
worker), so it holds only plain values. A real device is named in ``device``
either as a link, a path or a pyserial URL (``/dev/ttyACM0``, a pty,
``socket://127.0.0.1:PORT``) to a device speaking docs/device-protocol.md,
opened in the worker by studyapp/device/link_device.py with the ``device_*``
settings below; or as ``"module:factory"``, a driver of one's own whose
factory is called with the rate in the worker.
"""

from dataclasses import dataclass, field

from studyapp.device.link_device import DEFAULT_LATENCY, DEFAULT_PACKET, DEFAULT_RAMP_MS, SILENCE
from studyapp.engine.load_margin import hang_timeout_for, load_per_core
from studyapp.engine.safety import SafetyLimits
from studyapp.errors import ParameterError
from studyapp.model.sources import LVT_SENSOR, with_pseudo_sources

BLOCK_PERIOD = 0.002  # s: default block length; commands and MIDI act at block boundaries
TELEMETRY_MAX = 60.0  # s of telemetry the rings may keep (a minute at 96 kHz: ~1 GB with all estimators)
HANG_TIMEOUT_MAX = 5.0  # s: a watchdog slower than that watches nothing
HANG_TIMEOUT = 0.08  # s: the heartbeat bound on a machine that is not busy (load_margin.py: more when it is)


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
    bowing: bool = True  # the bow on the string from the first sample; a session starts it lifted (silent)
    f0: float | None = None  # Hz; None: the model's default
    seed: int = 0
    block: int | None = None  # samples per block; None: BLOCK_PERIOD worth
    audio: str = "null"  # device | device:NAME | wav:FILE | null  (audio.parse)
    lead: float = 0.03  # s of audio queued ahead of a device
    midi: str = "none"  # PORT | first | virtual | none  (midi.open_input)
    midi_map: dict | None = None  # protocol's map (midi.ControlMap.from_protocol); None: LPD8 factory
    actions: dict | None = None  # control -> action (model/controls.py); None: commands.default_actions
    safety: SafetyLimits = field(default_factory=SafetyLimits)
    telemetry_seconds: float = 4.0  # history kept in the rings
    realtime: bool = True  # ask for SCHED_FIFO for the worker's loop thread (falls back silently)
    device: str | None = None  # a link (path or URL) or "module:factory" of a driver; None: the simulated device
    device_latency: int = DEFAULT_LATENCY  # samples a link device's force is answered ahead of its sensor sample
    device_packet: int = DEFAULT_PACKET  # samples per sensor frame of a link device
    device_calibration: str | None = None  # a TOML file of calibrations keyed by serial number (calibration_file.py)
    device_ramp_ms: int = DEFAULT_RAMP_MS  # ms over which a link device's force ramps up from 0 after each ARM
    device_silence: float = SILENCE  # s without a frame from a link device that make it a device fault
    device_rearm: bool = False  # re-arm a link device at once after its watchdog trips (live); else the experimenter
    # s without a heartbeat before the force guard calls the worker hung: HANG_TIMEOUT, more on a busy machine
    hang_timeout: float = field(default_factory=lambda: hang_timeout_for(load_per_core(), HANG_TIMEOUT))
    # s without the force guard's heartbeat before the worker switches its own force off: the guard's
    # failure is the rarer one, so the deadline is looser than hang_timeout, sparing a loaded machine false trips
    guard_timeout: float = 0.2

    def block_size(self):
        """Samples per block. At most half ``hang_timeout`` worth: the heartbeat comes once a block, and the
        bound comes before any allocation (the ring holds at least four blocks)."""
        if self.block is not None:
            top = max(1, int(self.rate * self.hang_timeout / 2))
            if not 1 <= int(self.block) <= top:
                raise ParameterError(f"block = {self.block}: allowed is 1 to {top} samples "
                                     f"(half the watchdog's {1e3 * self.hang_timeout:g} ms at {self.rate:g} Hz)")
            return int(self.block)
        return block_samples(self.rate)

    def check_sizes(self):
        """Every size that becomes an allocation, bounded before any is made (``ParameterError``)."""
        if not 0.0 < float(self.hang_timeout) <= HANG_TIMEOUT_MAX:
            raise ParameterError(f"hang_timeout = {self.hang_timeout}: allowed is above 0 and up to "
                                 f"{HANG_TIMEOUT_MAX:g} s")
        if not 0.0 < float(self.telemetry_seconds) <= TELEMETRY_MAX:
            raise ParameterError(f"telemetry_seconds = {self.telemetry_seconds}: allowed is above 0 and up to "
                                 f"{TELEMETRY_MAX:g} s")
        return self.block_size()

    def link_options(self):
        """The keyword arguments of ``LinkDevice`` for a link ``device``."""
        return {"latency": self.device_latency, "packet": self.device_packet, "calibration": self.device_calibration,
                "ramp_ms": self.device_ramp_ms, "silence": self.device_silence}

    def sources(self):
        """The velocity sources a pad can select, in the scene's order."""
        names = list(self.estimators) if isinstance(self.estimators, dict) else list(self.estimators)
        return with_pseudo_sources(names)
