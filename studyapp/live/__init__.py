"""A live study session over the real-time engine, without Qt.

``controller.SessionController`` (the session as a state machine),
``engine_host.EngineHost`` (one engine, started and stopped without blocking),
``engine_loop.EngineLoop`` (the runner's loop, played by the engine),
``simulated_session`` (the simulated participant through a console's
controls), ``scope_buffer`` (what a scope draws), ``evented`` (model events
for views). The Qt widgets that show all this live in ``studyapp.gui``.
"""
