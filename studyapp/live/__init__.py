"""A live study session over the real-time engine, without Qt.

``controller.SessionController`` (the facade the views use) and its parts:
``states`` (the state machine), ``apparatus`` (the engine, ``engine_host``,
and the trial's loop, ``engine_loop``: the only senders of commands to the
worker), ``steps`` (a trial or page started, held, ended), ``controls``
(knobs and pads: routing, pickup, page settle, ``knob_latency``), ``hand``
(the bow and the gesture), ``trial_media`` (the audio recording and its
cues, the reference tone, trial health), ``master_sound``. Also
``simulated_session`` (the simulated participant through a console's
controls), ``headless_audio`` (the audio archive of a headless run),
``scope_buffer`` (what a scope draws), ``evented`` (model events for views).
The Qt widgets that show all this live in ``studyapp.gui``.
"""
