"""The headphone level check calibrated to the stimulus: the tone as loud as the bowed string.

A calibration page (``pages``) without ``level_dbfs`` plays its reference tone
at the RMS of the string as the participant will mostly hear it: bowed with
the protocol's gesture at the protocol's F_max, the typical level computed from
the model (``model.stimulus_level.typical_rms_dbfs``: the median over the
conditions of the median 100 ms RMS), so it follows any change to the model.
The protocol's F_max (``stimulus_fmax``) is the constant F_max of the first
task that has one (the rating task's 1 N in sinclair2014); a protocol with
only an adjustment task takes the middle of its knob's logarithmic range,
ceiling x 10^(-decades / 2). The tone's peak is its RMS + 3.01 dB (a sine).

The level is fixed when the session's schedule is made (the page is stored
whole in session.json, so a resumed session plays the same tone), and stated
on the page.
"""

from dataclasses import replace

from studyapp.model.stimulus_level import tone_peak_dbfs, typical_rms_dbfs


def stimulus_fmax(protocol):
    """``(fmax, task)``: the F_max the participant mostly hears, and the task it comes from."""
    for task in protocol.tasks:
        fmax = getattr(protocol.task(task), "fmax", None)
        if fmax:
            return float(fmax), task
    for task in protocol.tasks:
        spec = protocol.task(task)
        if hasattr(spec, "ceiling"):
            return float(spec.ceiling) * 10.0 ** (-float(spec.decades) / 2.0), task
    return 1.0, None


def stimulus_rms_dbfs(protocol):
    """``(rms dBFS, fmax, task)``: the typical RMS of the string at the protocol's F_max (the model's)."""
    fmax, task = stimulus_fmax(protocol)
    conditions = protocol.task(task).conditions if task else ("LVT",)
    params = {c: protocol.estimator_params(c) for c in conditions}
    return typical_rms_dbfs(protocol.rate, protocol.gesture, fmax, params, seed=protocol.seed), fmax, task


def calibrated(page, protocol):
    """``page`` with its tone's level set to the stimulus's, if the protocol left it to be computed."""
    if page.kind != "calibration" or page.level_dbfs is not None:
        return page
    rms, fmax, task = stimulus_rms_dbfs(protocol)
    statement = (f"The tone is as loud as the bowed string in this study: {rms:.1f} dBFS RMS "
                 f"(peak {tone_peak_dbfs(rms):.1f} dBFS), the string's typical level at F_max = {fmax:g} N"
                 f"{f' (the {task} task)' if task else ''}.")
    return replace(page, level_dbfs=round(tone_peak_dbfs(rms), 2), note=statement)  # the experimenter's, not on the page
