"""A session's run sheet: its plan, before Start (``studyapp plan``, the console's "Run sheet").

For a participant without a session the plan is what ``Session.create``
would build now: the enrolment index of the participant's kind (real or
simulated, ``enrolment``), the order row (``--order-row``, or the enrolment
index mod L), and the schedule of that row (``schedule.build_schedule``). It
is a prediction: the row is fixed when the session starts, and a participant
enrolled first would take it; the sheet says so. For a participant with a
session the plan is the stored one (session.json), with the steps done so
far ticked.

Estimated duration: per step, the median ``duration`` of the responses of
that task's real (not simulated, not practice) trials already recorded in
the study's results, when there are any; otherwise the task type's
``typical_duration`` (the paper's "under 5 minutes" for the rating task, our
stated guesses elsewhere: task modules). Pages always use the typical
figure (their reading time is not a response's duration). The total is a
planning figure, not a promise.

``plan_markdown`` writes the sheet as Markdown: the same text reads as plain
text on a terminal or on paper (columns padded), renders as a page in any
Markdown viewer and in the console (``QTextBrowser.setMarkdown``), and
converts to HTML or PDF with pandoc. With ``blind`` the sheet names no
condition (the console's blinding switch): steps are described by the task
type's blind-safe ``heading``.
"""

import statistics
from dataclasses import dataclass, field
from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment.enrolment import enrolment_index, is_simulated
from studyapp.experiment.schedule import Trial, build_schedule
from studyapp.experiment.session import check_participant
from studyapp.experiment.session_description import read_description, session_folders
from studyapp.experiment.session_files import EVENTS_FILE
from studyapp.experiment.results_folder import used_rows_text
from studyapp.experiment.session_info import check_order_row, order_rows
from studyapp.experiment.session_log import read_log
from studyapp.experiment.tasks import task_type


@dataclass
class PlannedStep:
    trial: Trial
    seconds: float
    recorded: bool  # the estimate is the median of recorded trials (else the task type's typical figure)
    done: bool = False


@dataclass
class RunPlan:
    protocol: object
    participant: str
    simulated: bool
    order_row: int
    order_rows: int
    order_source: str  # "enrolment", "set", or "stored"
    steps: list
    session: Path | None = None  # the stored session the plan comes from (None: predicted)
    squares: dict = field(default_factory=dict)  # task -> {"rows": n, "rows_used": [...]}
    results: Path | None = None  # the results folder (absolute)
    used: str = ""  # the order rows the study's participants of this kind already have (results_folder.py)

    @property
    def seconds(self):
        return sum(step.seconds for step in self.steps if not step.done)


def make_plan(protocol, participant, results, order_row=None, simulated=False):
    """The ``RunPlan`` of ``participant`` under ``protocol`` and the results folder ``results``."""
    check_participant(participant)
    order_row = check_order_row(protocol, order_row)
    study_folder = Path(results) / protocol.study
    typical = _recorded_durations(study_folder)
    existing = session_folders(study_folder / participant)
    if existing:
        plan = _stored_plan(protocol, participant, existing[-1], order_row, typical)
        plan.results, plan.used = Path(results), used_rows_text(study_folder, plan.simulated)
        return plan
    index = enrolment_index(study_folder, participant, simulated)
    rows = order_rows(protocol)
    source = "enrolment" if order_row is None else "set"
    row = index % rows if order_row is None else order_row
    schedule, squares = build_schedule(protocol, index, order_row=row)
    return RunPlan(protocol, participant, bool(simulated), row, rows, source,
                   [_planned(protocol, trial, typical) for trial in schedule], squares=squares,
                   results=Path(results), used=used_rows_text(study_folder, simulated))


def _stored_plan(protocol, participant, folder, order_row, typical):
    info, _ = read_description(folder)
    if info["protocol"]["sha256"] != protocol.sha256:
        raise UserError(f"{protocol.path}: differs from the protocol of session {folder} "
                        f"(sha256 {info['protocol']['sha256'][:12]}...): allowed is the protocol file the session "
                        "started with")
    if order_row is not None and order_row != info.get("order_row"):
        raise UserError(f"--order-row {order_row}: session {folder} has order row {info.get('order_row')}: "
                        "allowed is to leave it out for a participant who has a session")
    done = {e.get("step") for e in read_log(folder / EVENTS_FILE).events if e.get("type") == "response"}
    steps = []
    for stored in info["schedule"]:
        trial = Trial.from_dict(stored)
        step = _planned(protocol, trial, typical)
        step.done = trial.step in done
        steps.append(step)
    return RunPlan(protocol, participant, is_simulated(info), info.get("order_row", info.get("participant_index", 0)),
                   info.get("order_rows", order_rows(protocol)), "stored", steps, session=folder,
                   squares=info.get("latin_squares", {}))


def _planned(protocol, trial, typical):
    kind = task_type(trial.task)
    if trial.page is None and trial.task in typical:
        return PlannedStep(trial, typical[trial.task], recorded=True)
    return PlannedStep(trial, float(kind.typical_duration(protocol.specs.get(trial.task), trial)), recorded=False)


def _recorded_durations(study_folder):
    """{task: median duration (s)} of the real, non-practice responses recorded under ``study_folder``."""
    if not Path(study_folder).is_dir():
        return {}
    from studyapp.experiment.export import export_responses  # pandas: only when sessions are counted

    try:
        frame = export_responses(study_folder, problems=[])  # unreadable sessions: simply not counted
    except UserError:
        return {}
    frame = frame[~frame["simulated"] & ~frame["practice"] & frame["duration"].notna()]
    # one duration per response (a rating response makes a row per knob)
    per_response = frame.drop_duplicates(["participant", "session", "step"])
    return {task: float(statistics.median(group["duration"].astype(float)))
            for task, group in per_response.groupby("task")}


def _count(n, word):
    return f"{n} {word}{'' if n == 1 else 's'}"


def _clock(seconds):
    minutes, secs = divmod(round(seconds), 60)
    return f"{minutes}:{secs:02d}"


def _long(seconds):
    minutes = round(seconds / 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min" if hours else f"{minutes} min"


def _what(step, blind):
    trial = step.trial
    kind = task_type(trial.task)
    if trial.page is not None:
        return f"{trial.page.kind}: {trial.page.title}" if trial.page.title else trial.page.kind
    text = kind.heading(trial) if blind else kind.describe(trial)
    return f"practice {text}" if trial.practice else text


def _order_line(plan):
    if plan.order_source == "stored":
        return f"order row **{plan.order_row}** of {plan.order_rows} (stored in the session)"
    if plan.order_source == "set":
        return f"order row **{plan.order_row}** of {plan.order_rows} (set with --order-row)"
    kind = "simulated" if plan.simulated else "real"
    return (f"order row **{plan.order_row}** of {plan.order_rows} (enrolment: the next {kind} participant's; "
            "fixed when the session starts, so a participant enrolled first would take it)")


def _conditions(plan, blind):
    if blind:
        return ["Condition names hidden (blinding)."]
    lines = []
    for task in plan.protocol.tasks:
        trials = [s.trial for s in plan.steps if s.trial.task == task]
        real = [t for t in trials if not t.practice]
        practice = [t for t in trials if t.practice]
        used = plan.squares.get(task, {})
        rows = ", ".join(str(r) for r in used.get("rows_used", []))
        word = "row" if len(used.get("rows_used", [])) == 1 else "rows"
        lines.append(f"### {task}: {len(real)} trial{'' if len(real) == 1 else 's'}"
                     + (f", Latin-square {word} {rows} of {used['rows']}" if rows and "rows" in used else ""))
        lines.append("")
        if real and real[0].condition is None:  # one trial over all its conditions: the knob assignment
            for t in real:
                lines.append("- " + ", ".join(f"knob {k + 1}: {c}" for k, c in enumerate(t.conditions)))
        else:
            by_number = {}
            for t in real:
                by_number.setdefault(t.trial, []).append(t.condition)
            for number, names in by_number.items():
                lines.append(f"- repetition {number}: {', '.join(names)}")
        if practice:
            lines.append(f"- practice first: {'; '.join(task_type(t.task).describe(t) for t in practice)}")
        lines.append("")
    return lines


def plan_markdown(plan, blind=False):
    """The run sheet of ``plan`` as Markdown (module docstring)."""
    p = plan.protocol
    steps = plan.steps
    done = sum(s.done for s in steps)
    by_phase = {}
    for s in steps:
        if not s.done:
            key = "pages" if s.trial.page is not None else s.trial.task
            by_phase[key] = by_phase.get(key, 0.0) + s.seconds
    parts = ", ".join(f"{k} {_long(v)}" for k, v in by_phase.items())
    recorded = sorted({s.trial.task for s in steps if s.recorded})
    basis = (f"medians of recorded real trials for {', '.join(recorded)}; the task types' typical figures "
             "for the rest" if recorded else "the task types' typical figures (no recorded real trials yet)")
    where = (f"session `{plan.session.name}`: {done} of {len(steps)} steps done" if plan.session is not None
             else "no session yet")
    lines = [
        f"# Run sheet: {p.study}, participant {plan.participant}",
        "",
        f"- Protocol: `{p.path}` (sha256 `{p.sha256[:12]}`), study **{p.study}**, {p.rate:g} Hz",
        f"- Participant: **{plan.participant}**{' (simulated)' if plan.simulated else ''}, {where}",
        f"- Order: {_order_line(plan)}",
        *([f"- Results folder: `{plan.results}`; {plan.used}"] if plan.results is not None else []),
        f"- Steps: {len(steps)} ({_count(sum(s.trial.page is not None for s in steps), 'page')}, "
        f"{_count(sum(s.trial.practice for s in steps), 'practice trial')}, "
        f"{_count(sum(s.trial.page is None and not s.trial.practice for s in steps), 'trial')})",
        (f"- Estimated duration{' still to run' if done else ''}: **{_long(plan.seconds)}** ({parts}); "
         f"from {basis}" if parts else "- Nothing left to run"),
        "",
        "## Conditions in order",
        "",
        *_conditions(plan, blind),
        "## Steps",
        "",
    ]
    rows = [("step", "phase", "what", "est.", "done")]
    for s in steps:
        phase = "page" if s.trial.page is not None else "practice" if s.trial.practice else "trial"
        rows.append((str(s.trial.step + 1), phase, _what(s, blind).replace("|", "/"),
                     _clock(s.seconds) + ("*" if s.recorded else ""), "x" if s.done else " "))
    widths = [max(len(r[k]) for r in rows) for k in range(len(rows[0]))]
    for number, row in enumerate(rows):
        lines.append("| " + " | ".join(cell.ljust(w) for cell, w in zip(row, widths)) + " |")
        if number == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    lines += ["", "est.: m:ss; * the median of recorded real trials.", "",
              "## Notes", "", "Date and time: ______________   Experimenter: ______________", ""]
    return "\n".join(lines)
