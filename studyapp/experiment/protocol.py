"""A study protocol: a TOML file, validated on load.

A protocol says everything a session needs (paper Sec. 8): the haptic rate,
the estimator parameters (Table 1 unless overridden), the study-wide seed of
the Latin squares, the title the participant's screen shows (``participant_title``,
neutral by default: the study's ``title`` may state its aim, which the
participant must not see), the tasks to run in order, and one table per task: its
conditions, instructions and fields, which the task type reads and checks
(``studyapp.experiment.tasks``; e.g. the rating task's constant F_max, 1 N in
the paper, or the adjustment knob's F_max ceiling and how many decades its
logarithmic map spans), and the pages the participant reads between trials
(``[[pages]]``, ``studyapp.experiment.pages``). ``docs/experiment.md`` lists
every field.

Nothing starts on an invalid protocol, and nothing is enrolled:
``load_protocol`` raises one ``UserError`` whose single line names the file,
the field and what is allowed. Every number has a finite range that the model
accepts; NaN and infinities are refused.

The protocol's F_max ceiling (``fmax_ceiling``) is the engine's hard clamp
for the whole study: every task, the console's preview and the live knob
(engine/safety.py ``SafetyLimits.fmax_ceiling``). It is ``[apparatus]
fmax_ceiling`` when given, else the largest F_max the tasks use (the rating's
and listen task's ``fmax``, the adjustment knob's ``ceiling``); at most the
motors' sustained limit, ``SAFE_CEILING`` (60 N for the TGR). A task's F_max
above it is refused here, so no value is logged at one level and applied at
another.
The protocol's hash is the SHA-256 of the file's bytes, so two sessions ran the
same study exactly when their hashes agree.
"""

import hashlib
import re
from dataclasses import dataclass, field
from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment.fields import table_fields
from studyapp.experiment.pages import parse_pages
from studyapp.experiment.task_type import Bounds
from studyapp.experiment.tasks import protocol_task_names as task_names
from studyapp.experiment.tasks import task_type
from studyapp.io.small_files import parse_toml, read_bytes
from studyapp.model.calibration import F0
from studyapp.model.limits import RATE_PER_F0_MIN, SESSION_GESTURES, SUSTAINED_FORCE
from studyapp.model.playable import min_rate

SAFE_CEILING = SUSTAINED_FORCE  # N: the motors' sustained limit, the engine's default ceiling
FMAX_FIELDS = ("fmax", "ceiling")  # the task fields that set an F_max level

NAME_PATTERN = re.compile(r"[A-Za-z0-9_-]{1,32}")
NAME_ALLOWED = "1 to 32 letters, digits, '_' or '-'"
# what the participant's screen calls the study unless [study] participant_title says otherwise: the
# protocol's own title often states the study's aim, which must not reach the participant (blinding)
PARTICIPANT_TITLE = "Listening study"


@dataclass(frozen=True)
class Protocol:
    path: str
    text: str
    sha256: str
    study: str
    title: str
    tasks: tuple
    seed: int
    rate: float
    knobs: int
    pads: int
    gesture: str
    estimators: dict = field(default_factory=dict)
    specs: dict = field(default_factory=dict)  # task name -> its validated spec (the task type's parse)
    pages: tuple = ()  # the [[pages]] (studyapp.experiment.pages.Page), in file order
    participant_title: str = PARTICIPANT_TITLE  # the title the participant sees (never ``title``)
    fmax_ceiling: float = SAFE_CEILING  # N: the engine's hard clamp for this study (module docstring)

    def task(self, name):
        return self.specs[name]

    def estimator_params(self, name):
        """The parameter overrides for estimator ``name`` ({} = Table 1 defaults)."""
        return dict(self.estimators.get(name, {}))

    def settings(self):
        """A JSON-ready summary of the validated protocol (stored in session.json).

        ``conventions``: what the estimators' numbers mean, for every estimator
        that has conventions, with this protocol's parameters
        (``studyapp.estimators.conventions``).
        """
        from studyapp import estimators  # numba: only when settings are asked for (parse_protocol)
        from studyapp.estimators import conventions

        out = {
            "study": self.study,
            "title": self.title,
            "participant_title": self.participant_title,
            "tasks": list(self.tasks),
            "seed": self.seed,
            "rate": self.rate,
            "knobs": self.knobs,
            "pads": self.pads,
            "gesture": self.gesture,
            "fmax_ceiling": self.fmax_ceiling,
            "estimators": {k: dict(v) for k, v in self.estimators.items()},
            "conventions": conventions.record({n: self.estimator_params(n) for n in estimators.names()}),
            "pages": [page.to_dict() for page in self.pages],
        }
        for name in self.tasks:
            spec = self.task(name)
            out[name] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in spec.__dict__.items()}
        return out


def parse_protocol(text, source="<protocol>"):
    """Validate protocol ``text`` (TOML); ``source`` names the file in error messages."""
    # the estimators compile with numba: imported when a protocol is parsed, not when this module is
    from studyapp import estimators
    from studyapp.estimators.registry import spec as estimator_spec
    from studyapp.estimators.spec import RATE_MAX, RATE_MIN

    document = parse_toml(text, source)
    known_tables = ("study", "apparatus", "estimators", "pages", *task_names())
    for name in document:
        if name not in known_tables:
            raise UserError(f"{source}: [{name}] is not a known table: allowed are {', '.join(known_tables)}")

    study = table_fields(source, document, "study")
    name = study.string("name", NAME_ALLOWED, pattern=NAME_PATTERN)
    title = study.string("title", default=name)
    participant_title = study.string("participant_title", default=PARTICIPANT_TITLE)
    tasks_allowed = "a list of the tasks to run, in order, from: " + ", ".join(repr(t) for t in task_names())
    tasks = study.get("tasks", tasks_allowed)
    if (not isinstance(tasks, list) or not tasks or not all(isinstance(t, str) for t in tasks)
            or len(set(tasks)) != len(tasks) or any(t not in task_names() for t in tasks)):
        study.fail("tasks", f"= {tasks!r}", tasks_allowed)
    seed = study.integer("seed", 0, 2**32 - 1)
    study.finish()

    apparatus = table_fields(source, document, "apparatus")
    rate = apparatus.number("rate", RATE_MIN, RATE_MAX, "Hz")
    if rate < min_rate(F0):
        apparatus.fail("rate", f"= {rate:g}", f"at least {min_rate(F0):g} Hz: the string at f0 = {F0:g} Hz sounds "
                       f"at f0 only at rate >= {RATE_PER_F0_MIN:g} x f0 (docs/model.md)")
    knobs = apparatus.integer("knobs", 1, 64, default=8)
    pads = apparatus.integer("pads", 1, 64, default=8)
    gesture = apparatus.string("gesture", "one of " + ", ".join(SESSION_GESTURES), default="strokes")
    if gesture not in SESSION_GESTURES:
        apparatus.fail("gesture", f"= {gesture!r}", "one of " + ", ".join(SESSION_GESTURES))
    ceiling = None
    if "fmax_ceiling" in apparatus.values:
        ceiling = apparatus.number("fmax_ceiling", 0.0, SAFE_CEILING, "N (the motors' sustained limit)",
                                   low_open=True)
    apparatus.used.add("fmax_ceiling")
    apparatus.finish()

    known = estimators.names()
    overrides = {}
    table = table_fields(source, document, "estimators", required=False)
    for est, params in (table.values.items() if table else ()):
        if est not in known:
            table.fail(est, "is not an estimator", "one of " + ", ".join(known))
        if not isinstance(params, dict):
            table.fail(est, f"= {params!r}", "a table of parameters, e.g. LOWPASS = { cutoff_hz = 256.0 }")
        try:
            estimator_spec(est).validate(rate, params)
        except UserError as exc:
            raise UserError(f"{source}: [estimators] {est}: {exc}") from None
        overrides[est] = dict(params)

    specs = {}
    bounds = Bounds(estimators=tuple(known), knobs=knobs, pads=pads)
    for task in tasks:
        table = table_fields(source, document, task)
        specs[task] = task_type(task).parse(table, bounds)
        table.finish()
    for task in task_names():
        if task in document and task not in tasks:
            raise UserError(f"{source}: [{task}] is given but [study] tasks does not list it: "
                            f"allowed is to list it in tasks or remove the table")

    pages = parse_pages(source, document, tasks)
    ceiling = _fmax_ceiling(source, specs, ceiling)

    return Protocol(
        path=source,
        text=text,
        sha256=hashlib.sha256(text.encode("utf-8")).hexdigest(),
        study=name,
        title=title,
        tasks=tuple(tasks),
        seed=seed,
        rate=rate,
        knobs=knobs,
        pads=pads,
        gesture=gesture,
        estimators=overrides,
        specs=specs,
        pages=pages,
        participant_title=participant_title.strip(),
        fmax_ceiling=ceiling,
    )


def _fmax_ceiling(source, specs, given):
    """The protocol's F_max ceiling (module docstring); ``UserError`` for a task's F_max above it."""
    levels = [(task, key, float(getattr(spec, key))) for task, spec in specs.items() for key in FMAX_FIELDS
              if isinstance(getattr(spec, key, None), (int, float))]
    ceiling = given if given is not None else SAFE_CEILING
    where = ("[apparatus] fmax_ceiling" if given is not None
             else f"the motors' sustained limit; a lower one may be set as [apparatus] fmax_ceiling")
    for task, key, value in levels:
        if value > ceiling:
            raise UserError(f"{source}: [{task}] {key} = {value!r}: allowed is a number above 0 and up to "
                            f"{ceiling:g} N (the protocol's F_max ceiling: {where})")
    if given is not None:
        return given
    return max((value for _, _, value in levels), default=SAFE_CEILING)


def load_protocol(path):
    """Read and validate the protocol file at ``path``; its hash is the SHA-256 of its bytes."""
    path = Path(path)
    data = read_bytes(path, "protocol")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{path}: not UTF-8 text: allowed is a UTF-8 TOML file") from None
    return parse_protocol(text, str(path))
