"""The loop a device runs (protocol version 2): the study's estimators at the device's rate, as the host builds them.

The paper ran every estimator of its study concurrently on the device, each
sample (Sec. 8.4). A device loop here has

- every position-only estimator of the study (``STUDY``: LOWPASS, LEASTSQ,
  FOAW, LEVANT, LEVANTLP, KALPOS, KALLEV, KALFOAW; the adjustment task's
  conditions but LVT), and
- with an accelerometer, every estimator that reads acceleration too
  (``ACCELEROMETER``: KALMAN, KALLEVACC, KALFOAWACC, COMP1, COMP2),

each with Table 1's parameters at the rate (``{}``: the defaults), in that
order, which is the order of INFO's estimator list and of CONTROL's source
index. The LVT condition is the velocity sensor itself (CONTROL source -2,
model/sources.py), not an estimator of the list.

``device_loop(rate, accelerometer)`` builds the model's ``ClosedLoop`` on
those estimators exactly as the host builds its own (model/loop.py: the
bank, the string at calibration.F0, the motor limits, the velocity scale):
its ``control.arrays`` are what the C loop runs on (c_loop.CLoop) and what
the parameter image is computed from (loop_image.py).
"""

from studyapp.estimators.registry import SPECS

STUDY = ("LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS", "KALLEV", "KALFOAW")
ACCELEROMETER = tuple(name for name, spec in SPECS.items() if "acceleration" in spec.inputs)


def estimator_names(accelerometer):
    """The device loop's estimators, in INFO's order."""
    return STUDY + (ACCELEROMETER if accelerometer else ())


def names_of(kinds):
    """The estimator names of INFO's kinds (the host's side of ``estimator_names``)."""
    by_kind = {spec.kind: name for name, spec in SPECS.items()}
    return tuple(by_kind[k] for k in kinds)


def device_loop(rate, accelerometer):
    """The model's loop on the device loop's estimators at ``rate`` (Table 1 defaults), F_max 0, no audio.

    The loop's ``control.arrays`` are the C loop's; the simulated device it builds is never run.
    """
    from studyapp.model.loop import ClosedLoop, LoopConfig
    from studyapp.model.sources import LVT_SENSOR

    names = estimator_names(accelerometer)
    config = LoopConfig(rate=float(rate), estimators={n: {} for n in names}, source=LVT_SENSOR, fmax=0.0,
                        gesture="hold", audio=False, accelerometer=False)
    return ClosedLoop(config, judge=False)
