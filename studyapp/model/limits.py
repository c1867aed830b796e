"""The limits and names that several layers read: the motors' forces and travel, the gestures.

Plain numbers and tuples, importing nothing, so that the protocol's checks
(experiment/), the engine's safety and the console read them without loading
the simulation (numba, scipy). The model's own code (device.py, loop.py,
breakdown.py) reads them from here too: each is defined once.

Motor limits (the TGR, paper Sec. 4.1: "impulsive linear forces up to 200 N,
or 60 N sustained"): the loop clamps the force to +-IMPULSIVE_FORCE, and to
+-SUSTAINED_FORCE while its running RMS exceeds it (device.py). No F_max above
the impulsive limit makes sense, so FMAX_LIMIT is the largest any simulation,
protocol or logged event accepts; a study's own ceiling (protocol
``fmax_ceiling``) is at most SUSTAINED_FORCE.

The hand's reach (``HAND_REACH``) and the F_max knob's span (``KNOB_DECADES``)
bound what a command may ask (model/controls.py, engine/commands.py): a
target or knob law outside them is refused where the command is made and
again where the worker obeys it.

The string's lowest rate (``RATE_PER_F0_MIN``): the waveguide sounds within 1 %
of its pitch f0 only when the rate is at least 6 f0 (model/playable.py says
why and what was measured); below, every command and a protocol's validation
refuse the pair rather than compute with a string that does not play f0.

The gestures, the ways the virtual hand moves the handle (model/gestures.py),
are four sets, each for its own use:

    GESTURES            every gesture the loop runs (loop.make_gesture)
    SESSION_GESTURES    a protocol's [apparatus] gesture: all but playback, which needs a recorded trajectory
    CONSOLE_GESTURES    what the experimenter's console offers: scripted strokes, a held handle, the mouse
    BREAKDOWN_GESTURES  what the stability breakdown search bows with (breakdown.py)
"""

TRAVEL = 0.011  # m: the handle's end stops at +-TRAVEL
IMPULSIVE_FORCE = 200.0  # N
SUSTAINED_FORCE = 60.0  # N RMS
FMAX_LIMIT = IMPULSIVE_FORCE  # N: nothing above the motors' impulsive limit makes sense
RATE_PER_F0_MIN = 6.0  # the lowest rate / f0 at which the string sounds at f0 (model/playable.py)
HAND_REACH = 0.1  # m: the farthest hand target from the centre a command accepts (9 times the end stop's TRAVEL)
KNOB_DECADES = (0.1, 12.0)  # the decades an F_max knob may span (a protocol's adjustment ``decades``, a command's)

GESTURES = ("strokes", "strokes-validation", "hold", "live", "playback")
SESSION_GESTURES = tuple(g for g in GESTURES if g != "playback")
CONSOLE_GESTURES = ("strokes", "hold", "live")
BREAKDOWN_GESTURES = ("hold", "strokes")
