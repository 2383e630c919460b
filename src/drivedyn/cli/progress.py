"""Progress display of a run: a rich progress bar on a terminal, silence elsewhere; and
Ctrl-C taken between steps.

Ctrl-C during the time loop is held until the loop's next progress call (after every batch
of outputs, or every accepted step with ``--verbose``) and raised there, in this module's
own code: the run then stops at an accepted step and keeps its results
(:meth:`drivedyn.solver.simulation.Simulation.advance`). Raised wherever the signal lands,
the interrupt can strike inside a library's code (a logging handler, numba's dispatcher)
that clears it or leaves a lock taken, and the run does not stop. Before the first
progress call (kernels loading, the initial state) Ctrl-C interrupts at once.
"""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager


@contextmanager
def _interrupt_between_steps() -> Iterator[Callable[[], None]]:
    """Yield ``check()``: it raises KeyboardInterrupt when Ctrl-C came since the first
    ``check()``; before that call Ctrl-C raises at once. The previous SIGINT handler is
    restored on exit (outside the main thread nothing is changed: ``check`` does nothing)."""
    if threading.current_thread() is not threading.main_thread():
        yield lambda: None
        return
    state = {"stepping": False, "pending": False}

    def on_sigint(signum, frame) -> None:
        if not state["stepping"]:
            raise KeyboardInterrupt
        state["pending"] = True

    def check() -> None:
        state["stepping"] = True
        if state["pending"]:
            state["pending"] = False
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        yield check
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def progress_bar(t_end: float, enabled: bool | None = None,
                 ) -> Iterator[Callable[[float, float, int], None]]:
    """Yield a ``progress(t, h, steps)`` callback for :func:`drivedyn.simulate`.

    On a terminal it drives a rich bar showing simulated time, steps per second and the
    current step size, refreshed at most 10 times a second (the callback itself costs about
    a microsecond per step); elsewhere (pipes, CI) it shows nothing. Either way Ctrl-C
    during the time loop is raised by the callback (see the module docstring).
    """
    if enabled is None:
        enabled = sys.stderr.isatty()
    with _interrupt_between_steps() as check:
        if not enabled:
            yield lambda t, h, n: check()
            return
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        bar = Progress(
            TextColumn("[bold]t = {task.fields[t]:.4g} s"),
            BarColumn(),
            TextColumn("{task.percentage:>3.0f}%"),
            TextColumn("{task.fields[rate]:>8.0f} steps/s"),
            TextColumn("h = {task.fields[h]:.2e} s"),
            TimeElapsedColumn(),
            transient=False,
        )
        task = bar.add_task("simulate", total=t_end, t=0.0, rate=0.0, h=0.0)
        state = {"last": 0.0, "t0": time.perf_counter()}

        def update(t: float, h: float, steps: int) -> None:
            check()
            now = time.perf_counter()
            if now - state["last"] < 0.1 and t < t_end:
                return
            state["last"] = now
            rate = steps / max(now - state["t0"], 1e-9)
            bar.update(task, completed=t, t=t, rate=rate, h=h)

        with bar:
            yield update
