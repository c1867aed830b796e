"""The console's device and rig check: the panel's choice to the controller, the engine's device records to the
panel, the prediction started for each engine, and the question at Start.

The prediction (rig_prediction.py) starts whenever an engine starts (a
protocol or device chosen, a session's engine): the request is that
protocol's adjustment conditions on that engine's rig (live/rig_check.py),
and a kept result shows at once. ``accepted()`` is asked before a new session:
on a rig whose verdict warns, or on a link whose check has not finished, the
experimenter must answer *Yes* ("Start the session on this rig anyway?",
*No* the default); the answer taken is logged (a console message, and a
``rig_check`` record in the session's log).
"""

from studyapp.errors import UserError
from studyapp.gui.rig_prediction import RigPrediction
from studyapp.live import rig_check


class RigCheckView:
    def __init__(self, console, predict=rig_check.predict):
        self.console = console
        self.controller = console.controller
        self.panel = console.setup.device_panel
        self.prediction = RigPrediction(predict, console)  # off the GUI thread
        self.request = None
        self.panel.device_chosen.connect(self.choose_device)
        self.prediction.progress.connect(self.panel.show_progress)
        self.prediction.finished.connect(lambda req, p: self.panel.show_verdict(rig_check.verdict(p, req.rig)))
        self.prediction.failed.connect(lambda why: self.panel.show_no_check(f"the rig check failed: {why}"))
        self.controller.events.device.connect(self.panel.show_info)
        self.controller.events.device_health.connect(self.panel.show_health)

    def choose_device(self, device):
        """Run on ``device`` (None: the simulated device; else a link's path or URL)."""
        try:
            self.controller.set_device(device)
        except UserError as exc:
            self.console.setup.show_error(str(exc))
            return False
        self.console.setup.show_error("")
        return True

    def engine_state(self, state):
        if state == "starting":
            self.check()
        elif state == "running" and self.controller.device_info is not None:
            self.panel.show_info(self.controller.device_info)  # it may have come before the state did

    def check(self):
        """Start (or show the kept) prediction of the protocol's adjustment conditions on the engine's rig."""
        rig = self.controller.rig()
        req = rig_check.request(self.controller.protocol, rig) if rig is not None else None
        self.request = req
        if req is None:
            self.panel.show_no_check("no adjustment task in this protocol: no breakdown to predict")
        elif self.prediction.result(req) is None:
            self.panel.show_predicting(rig)
        self.prediction.run(req)

    def accepted(self):
        """Before a new session: None if the rig check warns (or is not ready on a link) and the experimenter
        does not go on; else the records to log (the warning taken: rig_check.record)."""
        if self.request is None and self.controller.protocol is not None:
            self.check()  # no engine has started yet (``--start``): ``studyapp run`` may have predicted it
        req = self.request
        if req is None:
            return ()
        prediction = self.prediction.result(req)
        verdict = None
        if prediction is None:
            if not rig_check.needs_check(req.rig):
                return ()
            text = (f"The rig check (the model's bowing breakdown at this rig's {req.rig.latency_words} link "
                    "latency) is still running. Start the session without it?")
        else:
            verdict = rig_check.verdict(prediction, req.rig)
            if not verdict.warns:
                return ()
            text = verdict.warning[len("warning: "):]
            text = f"{text[0].upper()}{text[1:]}.\n\nStart the session on this rig anyway?"
        if not self.console.confirm("The rig may not show the effect", text):
            return None
        self.controller.message(f"rig check: started anyway: {text.splitlines()[0]}", level="warning")
        return () if verdict is None else (rig_check.record(verdict, started_anyway=True),)
