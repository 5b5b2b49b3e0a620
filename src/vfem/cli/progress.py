"""What ``vfem run`` shows while it solves: a progress bar over the steps."""

from __future__ import annotations

import os
import sys

#: set by ``vfem run --ranks`` for the ranks it launches: "1" when the user's screen is a
#: terminal, "0" when the output goes to a file or a pipe (mpiexec gives the ranks a
#: pseudo-terminal either way, so without it a run piped to a file wrote carriage returns,
#: ESC[K and a line per contact iteration into it)
TTY_ENV = "VFEM_TTY"


def is_terminal(stream) -> bool:
    """Whether ``stream`` shows on a terminal: for the standard output of a rank that an MPI
    launcher started, what ``vfem run --ranks`` said (:data:`TTY_ENV`); else the stream's own
    ``isatty`` (a stray ``VFEM_TTY`` in a serial run, or another stream, changes nothing)."""
    from .. import parallel

    said = os.environ.get(TTY_ENV)
    if said in ("0", "1") and stream is sys.stdout and parallel.launched_size() > 1:
        return said == "1"
    return bool(getattr(stream, "isatty", lambda: False)())


class Progress:
    """A progress bar over the steps (redrawn in place on a terminal, a line per step
    otherwise): load factor, the step's contact iterations and its final errors."""

    def __init__(self, load_factors=None, enabled: bool = True, stream=None):
        self.factors = list(load_factors or [])
        self.total = len(self.factors)
        self.enabled = enabled
        self.stream = stream or sys.stdout
        self.tty = is_terminal(self.stream)
        self.done = 0  # scheduled steps completed (a cut step completes only at its target)
        self.steps_seen = 0  # converged steps, cut ones included
        self.label = ""  # the case under way, in a run of several (wedge): "case 3: "
        self.after_step = None  # called after each converged step (the results folder's record)

    def start_case(self, name: str) -> None:
        """A run of several analyses (the wedge's cases) starts the next one, ``name``: its
        progress lines are prefixed with it and count its steps from the start."""
        if self.enabled and self.tty and self.steps_seen:
            self.stream.write("\n")
        self.label = f"{name}: "
        self.done = self.steps_seen = 0

    def __call__(self, step) -> None:
        if self.after_step is not None:
            self.after_step()
        if not self.enabled:
            return
        self.steps_seen += 1
        if self.done < self.total and step.load_factor == self.factors[self.done]:
            self.done += 1
        h = step.history[-1] if step.history else None
        pen = h.max_penetration if h else 0.0
        eq = h.max_equilibrium_error if h else 0.0
        yielded = getattr(step, "yielded", None)  # (a plastic body's points)
        text = (f"step {step.step:3d}  load factor {step.load_factor:7.4f}  "
                f"{step.iterations:3d} iterations  penetration {pen:.2e}  "
                f"equilibrium error {eq:.2e}"
                + (f"  {sum(yielded.values())} points yielded" if yielded else "")
                + (f"  ({step.cuts} cuts)" if step.cuts else ""))
        if self.total:
            width = 20
            part = 0.0  # how far a cut step has come towards its scheduled target
            if self.done < self.total:
                prev = self.factors[self.done - 1] if self.done else 0.0
                part = min(1.0, max(0.0, (step.load_factor - prev)
                                    / (self.factors[self.done] - prev)))
            filled = round(width * (self.done + part) / self.total)
            text = f"[{'#' * filled}{'.' * (width - filled)}] {text}"
        text = self.label + text
        if self.tty:
            self.stream.write("\r\033[K  " + text)
            self.stream.flush()
        else:
            print("  " + text, file=self.stream, flush=True)

    def iteration(self, record) -> None:
        """On a terminal, the contact iteration under way and its errors (Analysis.run)."""
        if not (self.enabled and self.tty):
            return
        self.stream.write(f"\r\033[K  {self.label}step {self.steps_seen + 1:3d}  iteration "
                          f"{record.iteration:3d}  penetration {record.max_penetration:.2e}  "
                          f"equilibrium error {record.max_equilibrium_error:.2e}")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()
