"""Progress of a long optimisation on stderr: the best objective per estimator.

One line at most every ``interval`` seconds (and a last one at the end):
iteration, parameter sets evaluated, elapsed time, then for each estimator its
best F_g under the scale in force and, after a slash, how many new sets in a
row have not improved it (it stops at the patience), or ``*`` once it has
stopped searching. ``prefix`` starts every line (``studyapp tradeoff`` names
the rate there).
On a terminal the line is redrawn in place; in a log each update is a line.
"""

import sys
import time


class Progress:
    def __init__(self, stream=None, interval=2.0, prefix=""):
        self.prefix = str(prefix)
        self.stream = sys.stderr if stream is None else stream
        self.interval = float(interval)
        self.started = time.monotonic()
        self.last = -float("inf")
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def __call__(self, iteration, evaluated, objectives, done, final=False, waiting=None):
        now = time.monotonic()
        if not final and now - self.last < self.interval:
            return
        self.last = now
        waiting = waiting or {}
        parts = [
            f"{name} {value:.4g}" + ("*" if name in done else f"/{waiting[name]}" if name in waiting else "")
            for name, value in objectives.items()
        ]
        line = self.prefix + f"iter {iteration} sets {evaluated} {now - self.started:.0f}s | " + "  ".join(parts)
        if self.tty:
            self.stream.write("\r\033[K" + line + ("\n" if final else ""))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()
