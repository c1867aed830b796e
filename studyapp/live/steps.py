"""A live session's steps: each trial or page started, held and ended on the engine. No Qt.

A trial gets its loop from the runner's ``make_loop``: the trial's knob
mapping (the task type's ``knob_actions``) tagged with a new number
(``trial_serial``), so the worker tags every sample and control with it, and
the trial's start is cued in the audio record at the same block. A page step
(welcome, instructions, a break, the headphone level check, ...) has no loop:
it holds the engine silent (F_max 0, the bow lifted, an empty knob mapping
tagged with the step's own number, so the confirm pad still reaches the page
as a pad press the worker reports back); a calibration page plays its
reference tone. Holding a step (pause, or a step started while the session
is not running) holds a trial's loop, or takes a page's tag and tone away.
When a step ends or is interrupted its tone stops, its knob latency and
trial health are logged, and knobs waiting for pickup wait for the next
step's level.
"""

from studyapp.live.apparatus import trial_actions


def make_loop(c, estimators, source, seed):
    """The runner's ``make_loop`` (``seed`` unused: the engine keeps the session's, engine_loop.py)."""
    c.trial_serial += 1
    c.devices.steps[c.trial_serial] = c.runner.trial.step
    task = c.runner.task
    positions = {f"knob{i + 1}": int(v) for i, v in task.knob_positions().items() if v is not None}
    loop = c.apparatus.loop(estimators, source, c.protocol.gesture, c.trial_serial,
                            trial_actions(c.runner.trial, task), positions)
    c.media.cue("start")  # at the block where the trial's mapping takes force
    return loop


def step_ends(c):
    """The current step is over (or interrupted): tone off, its latency and health logged, pickups reset."""
    c.media.reference_tone(False)
    c.controls.log_latency()
    c.media.log_health()
    c.controls.forget_pickups()


def start_step(c, held):
    """Start the first step without a response (the same one again after an interruption), ``held`` or not.

    Returns the step's trial, or None when none is left."""
    step_ends(c)
    trial = c.runner.start_trial()
    if trial is None:
        return None
    c.media.step_starts()
    page = trial.page
    if page is not None:
        c.controls.page_appears()
        c.trial_serial += 1
        c.devices.steps[c.trial_serial] = trial.step
        c.apparatus.hold_page(c.trial_serial)
        c.media.cue("start")  # a page's span in audio_cues.csv too (the level check's tone is recorded)
        c.media.reference_tone(page.kind == "calibration")
    if held:
        hold(c, True)
    return trial


def hold(c, on):
    """Hold the current step (True), or give it back: a trial's loop, or a page's tag and tone."""
    if c.runner.loop is not None:
        c.runner.loop.hold(on)
        return
    c.apparatus.tag(-c.trial_serial if on else c.trial_serial)
    c.media.reference_tone(not on)
