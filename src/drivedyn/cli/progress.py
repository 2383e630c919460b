"""Progress display of a run: a rich progress bar on a terminal, silence elsewhere."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager


@contextmanager
def progress_bar(t_end: float, enabled: bool | None = None,
                 ) -> Iterator[Callable[[float, float, int], None]]:
    """Yield a ``progress(t, h, steps)`` callback for :func:`drivedyn.simulate`.

    On a terminal it drives a rich bar showing simulated time, steps per second and the
    current step size, refreshed at most 10 times a second (the callback itself costs about
    a microsecond per step); elsewhere (pipes, CI) it does nothing.
    """
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        yield lambda t, h, n: None
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
        now = time.perf_counter()
        if now - state["last"] < 0.1 and t < t_end:
            return
        state["last"] = now
        rate = steps / max(now - state["t0"], 1e-9)
        bar.update(task, completed=t, t=t, rate=rate, h=h)

    with bar:
        yield update
