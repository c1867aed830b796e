"""Can this rig show the paper's effect? The predicted bowing breakdown of a protocol's adjustment conditions
at the rig's link latency, and the verdict the console and ``studyapp run`` give before a session. No Qt.

The rig (``Rig``): the simulated device is the paper's loop (latency 0), and
so is a device that runs the loop itself (protocol 2, device/loop_link.py: the
force for sample k from the sensors of sample k, on the device; the link
carries only its settings and telemetry); a device whose loop runs on the host
answers each sensor sample k with a force tagged k + L
(L = ``EngineConfig.device_latency`` samples, link_device.py), which the device
applies at its sample k + L: a pure delay of L samples, the model's link with
``latency = L / rate`` and no packets (model/link.py's special case P = 1,
J = 0; tests/device/test_link_lockstep.py shows the two loops equal sample
for sample). So the prediction needs no handshake: the latency the host
answers with is the one the model takes.

What is predicted (``request``): every condition of the protocol's adjustment
task(s), each with the protocol's estimator parameters, at the protocol's
rate, by ``model.link_prediction.predict`` (the breakdown search behind the
link, median over seeds). The verdict (``verdict``): LVT's breakdown over the
best estimator's (``lvt_margin``); below ``MARGIN`` = 1.5 the paper's effect
(LVT nearly twice the estimators, Sec. 8.3, Fig. 7) is not expected, and an
adjustment-task session is warned against (``warning``: the same line in the
console's question at Start and in ``studyapp run``'s progress).

A protocol without an adjustment task, or without LVT or another estimator in
it, has nothing to check (``request`` is None / the margin is nan: no
warning). ``PredictionCache`` keeps each result per ``Request.key``:
(protocol hash, latency, packet, rate), in memory and, for ``predict``'s own
results, on disk (``cache_path``) so a relaunch does not compute it again.
"""

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

from studyapp.io.atomic import atomic_open
from studyapp.model import link_prediction
from studyapp.model.link_prediction import MARGIN
from studyapp.model.sources import LVT_SENSOR, TRUE

ADJUSTMENT = "adjustment"
# what the experimenter can change, with the controls that exist (issue 41, item 10: the warning named a doc)
REMEDY = ("To change it: a device that runs the loop itself keeps the effect on any link (docs/devices.md, "
          "\"The loop on the device\"); or answer the device fewer samples ahead if its round trip allows "
          "(now {samples}): start the console with `studyapp gui --device LINK --device-latency SAMPLES` "
          "(`--device-silence SECONDS` for the silence bound), as `studyapp live` takes them")
SIMULATED, DEVICE_LOOP = "simulated", "device-loop"


@dataclass(frozen=True)
class Rig:
    """The device the loop runs on, as the model sees it: its link's latency and packet (s) at ``rate`` (Hz)."""

    kind: str  # "simulated" or "link"
    rate: float
    latency_samples: int = 0
    packet: float = 0.0

    @property
    def latency(self):
        return self.latency_samples / self.rate

    @property
    def words(self):
        """Where the loop runs, for the console and ``studyapp run``."""
        if self.kind == DEVICE_LOOP:
            return "the loop runs on the device: the paper's own loop (latency 0)"
        if self.kind == SIMULATED:
            return "the simulated device: the paper's own loop (latency 0)"
        return f"the loop runs on the host, {self.latency_words} across the link"

    @property
    def latency_ms(self):
        return 1e3 * self.latency

    @property
    def latency_words(self):
        """The link's latency as every command line counts it, samples, with its ms beside (issue 41 item 6)."""
        return f"{self.latency_samples} samples ({self.latency_ms:.2f} ms)"


def rig_of(config, loop=None):
    """The ``Rig`` of an ``EngineConfig``: simulated (latency 0), a device on a link that runs the loop itself
    (``loop`` "device", from its INFO: latency 0) or one the host's loop drives (its answer-ahead latency)."""
    if not config.device:
        return Rig(SIMULATED, float(config.rate))
    if loop == "device":
        return Rig(DEVICE_LOOP, float(config.rate))
    return Rig("link", float(config.rate), int(config.device_latency))


def needs_check(rig):
    """False for the paper's own loop (no link delay): the model's reference, where LVT's margin is the paper's."""
    return rig.latency_samples > 0 or rig.packet > 0


@dataclass(frozen=True)
class Request:
    """What to predict for a protocol on a rig."""

    conditions: tuple
    estimators: dict
    rig: Rig
    protocol_hash: str

    @property
    def key(self):
        return (self.protocol_hash, self.rig.latency, self.rig.packet, self.rig.rate)


def adjustment_conditions(protocol):
    """The conditions of the protocol's adjustment task(s), in the order they first appear."""
    names = []
    for task in protocol.tasks:
        if task == ADJUSTMENT:
            names += [n for n in protocol.task(task).conditions if n not in names]
    return tuple(names)


def request(protocol, rig):
    """The prediction the protocol needs on ``rig``; None without an adjustment task."""
    conditions = adjustment_conditions(protocol)
    if not conditions:
        return None
    return Request(conditions, {n: protocol.estimator_params(n) for n in conditions}, rig, protocol.sha256)


def predict(req, seeds=5, duration=link_prediction.DURATION, progress=None):
    """{condition: median breakdown F_max (N)} for ``req`` (link_prediction.predict; seconds of CPU per condition)."""
    return link_prediction.predict(list(req.conditions), req.rig.latency, rate=req.rig.rate, seeds=seeds,
                                   packet=req.rig.packet, estimators=req.estimators, duration=duration,
                                   progress=progress)


@dataclass(frozen=True)
class Verdict:
    prediction: dict
    rig: Rig
    margin: float  # LVT over the best estimator; nan when the protocol does not compare them

    @property
    def best(self):
        """The estimator with the largest predicted breakdown (not LVT nor TRUE); None without one."""
        others = {n: v for n, v in self.prediction.items() if n not in (LVT_SENSOR, TRUE)}
        return max(others, key=others.get) if others else None

    @property
    def warns(self):
        """True when LVT falls below ``MARGIN`` times the best estimator on this rig."""
        return not math.isnan(self.margin) and self.margin < MARGIN

    @property
    def text(self):
        """One line for the console's panel."""
        if math.isnan(self.margin):
            return "no LVT-versus-estimator comparison in this protocol's adjustment task"
        said = f"LVT {self.margin:.2f}x the best estimator ({self.best})"
        return f"{said}: below {MARGIN:g}x, the paper's effect is not expected" if self.warns else \
            f"{said}: at least {MARGIN:g}x, the paper's effect is expected"

    @property
    def warning(self):
        """The warning line before an adjustment-task session (None when the rig keeps the effect)."""
        if not self.warns:
            return None
        return (f"warning: at this rig's link latency of {self.rig.latency_samples} samples "
                f"({self.rig.latency_ms:.2f} ms at {self.rig.rate:g} Hz) the model predicts LVT's bowing "
                f"breakdown at {self.margin:.2f}x the best estimator's ({self.best}), below {MARGIN:g}x: the "
                "paper's effect (LVT nearly twice the estimators) is not expected on this rig. "
                f"{REMEDY.format(samples=self.rig.latency_samples)}")


def verdict(prediction, rig):
    return Verdict(dict(prediction), rig, link_prediction.lvt_margin(prediction))


def record(verdict_, started_anyway):
    """The session log's ``rig_check`` record: what the model predicted on this rig and what was done about it."""
    margin = verdict_.margin
    return {"type": "rig_check", "latency_ms": verdict_.rig.latency_ms, "rate": verdict_.rig.rate,
            "prediction": {n: (None if math.isinf(v) else v) for n, v in verdict_.prediction.items()},
            "lvt_margin": None if math.isnan(margin) or math.isinf(margin) else margin, "threshold": MARGIN,
            "warning": verdict_.warning, "started_anyway": bool(started_anyway)}


def rows(prediction):
    """(condition, F_max text) for a table, largest first (inf: "stable to 200 N")."""
    ordered = sorted(prediction.items(), key=lambda item: -item[1])
    return [(name, "stable to 200 N" if math.isinf(v) else f"{v:.2f} N") for name, v in ordered]


def cache_path():
    """The predictions kept between launches: ``$STUDYAPP_RIG_PREDICTIONS`` (a file; the tests' own), else
    ``$XDG_CACHE_HOME/studyapp/rig_predictions.json`` (~/.cache)."""
    given = os.environ.get("STUDYAPP_RIG_PREDICTIONS")
    if given:
        return Path(given)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "studyapp" / "rig_predictions.json"


class PredictionCache:
    """Predictions kept per ``Request.key`` (protocol hash, latency, packet, rate); with a ``path``, on disk too.

    The file (JSON, written whole: io/atomic.py) is read at start and written at each ``put``, so a relaunch
    (``gui --screenshot``, ``run`` then its console) shows a rig's prediction at once instead of minutes of
    searches (issue 41, item 10). Only ``predict``'s own results go there (``RigPrediction`` keeps a test's
    stand-in in memory). A file that cannot be read or written is ignored: it only saves time."""

    VERSION = 1

    def __init__(self, path=None):
        self.path = None if path is None else Path(path)
        self._kept = {}
        if self.path is not None:
            self._kept = self._load()

    def get(self, req):
        return self._kept.get(req.key)

    def put(self, req, prediction):
        self._kept[req.key] = dict(prediction)
        if self.path is not None:
            self._save()

    def _load(self):
        try:
            stored = json.loads(self.path.read_text())
            if stored.get("version") != self.VERSION:
                return {}
            return {(str(h), float(lat), float(pk), float(rate)): {n: math.inf if v is None else float(v)
                                                                  for n, v in prediction.items()}
                    for (h, lat, pk, rate), prediction in stored["predictions"]}
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return {}

    def _save(self):
        stored = {"version": self.VERSION,
                  "predictions": [[list(key), {n: None if math.isinf(v) else v for n, v in prediction.items()}]
                                  for key, prediction in self._kept.items()]}
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with atomic_open(self.path) as f:
                json.dump(stored, f)
        except OSError:
            pass
