"""Running the points of a sweep: on a Dask cluster (an embedded ``LocalCluster`` by default,
a running scheduler by address or scheduler file, or a client the caller made), or one after
another in this process (``scheduler="serial"``, for debugging and tiny sweeps).

Workers run one point at a time each (``threads_per_worker=1``: a point is single-threaded
numba and LAPACK; Dask's nannies already pin the BLAS/OpenMP threads of their workers to 1).
A point lost with its worker (killed, out of memory) is retried by Dask on another worker
(``distributed.scheduler.allowed-failures``, 3 by default); past that it comes back as a
``lost`` record, not an exception, and the next run of the sweep computes it again.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from drivedyn.sweeps.design import SweepInputError
from drivedyn.sweeps.evaluate import Task, evaluate_point

#: where the embedded cluster listens unless asked otherwise: this machine only
LOOPBACK = "127.0.0.1"


def lost_record(exc: BaseException) -> dict:
    """The record of a point whose evaluation never returned (worker lost, cancelled)."""
    return {"status": "lost", "message": f"{type(exc).__name__}: {exc}"[:500],
            "outputs": {}, "units": {}, "host": ""}


def _connect(scheduler: str, timeout: float) -> Any:
    from distributed import Client

    try:
        if Path(scheduler).is_file():
            return Client(scheduler_file=scheduler, timeout=timeout)
        return Client(scheduler, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SweepInputError(f"--scheduler {scheduler}: cannot connect to a Dask scheduler "
                              f"there ({type(exc).__name__}: {exc})") from None


def _default_client() -> Any:
    """The Dask client the caller made in this process (``distributed.Client()`` in a
    notebook), or None."""
    try:
        from distributed import default_client
    except ImportError:  # pragma: no cover - distributed is a dependency
        return None
    try:
        return default_client()
    except ValueError:
        return None


def run_tasks(tasks: list[Task], *, client: Any = None, scheduler: str | None = None,
              workers: int | None = None, host: str = LOOPBACK, timeout: float = 30.0,
              on_cluster: Callable[[str], None] | None = None) -> Iterator[tuple[int, dict]]:
    """Yield ``(task index, record)`` as the points finish, in completion order.

    Args:
        tasks: the points to compute.
        client: a ``distributed.Client`` to use (not closed here).
        scheduler: ``"serial"`` (this process, no Dask), a scheduler address
            (``tcp://host:8786``) or a scheduler file (``dask scheduler --scheduler-file``).
            None: the caller's default Dask client if there is one, else a new local cluster.
        workers: worker processes of the local cluster (default: the number of CPUs).
        host: the address the local cluster's scheduler, workers and dashboard listen on
            (default 127.0.0.1: nobody else on the network sees the sweep; "0.0.0.0" for
            every interface).
        timeout: seconds to wait for a scheduler to answer.
        on_cluster: called once with a one-line description of where the points run.
    """
    if scheduler == "serial":
        if on_cluster:
            on_cluster("serial: in this process, one point after another")
        for i, t in enumerate(tasks):
            yield i, evaluate_point(t)
        return
    if not tasks:
        return
    own_cluster = own_client = None
    try:
        if client is None and scheduler is not None:
            client = own_client = _connect(scheduler, timeout)
        if client is None:
            client = _default_client()
        if client is None:
            from distributed import Client, LocalCluster

            n = workers or os.cpu_count() or 1
            # scheduler, workers and dashboard on ``host`` only; the dashboard on a free port
            # (the default 8787 may be a user's own cluster's); silence_logs keeps worker
            # chatter off the terminal
            dash = f"[{host}]:0" if ":" in host else f"{host}:0"
            own_cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       host=host, dashboard_address=dash,
                                       silence_logs=logging.ERROR)
            client = own_client = Client(own_cluster)
        if on_cluster:
            info = client.scheduler_info()
            nw = len(info.get("workers", {}))
            threads = sum(w.get("nthreads", 0) for w in info.get("workers", {}).values())
            where = "local cluster" if own_cluster is not None else info.get("address", "")
            link = getattr(client, "dashboard_link", None)
            on_cluster(f"Dask {where}: {nw} worker(s), {threads} thread(s)"
                       + (f"; dashboard {link}" if link else ""))
        yield from _submit(client, tasks)
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()


def _submit(client: Any, tasks: list[Task]) -> Iterator[tuple[int, dict]]:
    from distributed import as_completed

    futures = {}
    for i, t in enumerate(tasks):
        fut = client.submit(evaluate_point, t, key=f"drivedyn-point-{t.key[:16]}-{i}",
                            pure=False)
        futures[fut] = i
    pending = set(futures)
    try:
        for fut in as_completed(list(futures)):
            pending.discard(fut)
            try:
                rec = fut.result()
            except Exception as exc:
                rec = lost_record(exc)
            yield futures[fut], rec
    finally:
        if pending:  # interrupted: do not leave work running on a shared cluster
            client.cancel(list(pending))
