"""Parameter sweeps on Dask: design parsing, bit-identity with separate commands,
exact sensitivities, the resumable cache, lost workers, an external scheduler, bad input."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.sweeps import (
    SweepInputError,
    SweepInterrupted,
    parse_metric,
    parse_sample,
    parse_vary,
    sweep,
)
from drivedyn.sweeps.design import grid, sensitivity

SPRING = """
# A block on a slide pushed by a constant force against a critically damped spring: at rest
# the spring deflects by F/k exactly.
[model]
name = "spring-block"

[[bodies]]
name = "block"
mass = "1 kg"
inertia = [1e-3, 1e-3, 1e-3]
position = ["1 m", 0, 0]

[[markers]]
name = "guide"
body = "ground"
position = ["1 m", 0, 0]
axis = [1, 0, 0]

[[markers]]
name = "shoe"
body = "block"
axis = [1, 0, 0]

[[markers]]
name = "anchor"
body = "ground"

[[elements]]
type = "Prismatic"
name = "slide"
marker_a = "guide"
marker_b = "shoe"

[[elements]]
type = "SpringDamper"
name = "spring"
marker_a = "anchor"
marker_b = "shoe"
stiffness = "1000 N/m"
damping = "63.2455532 N s/m"

[[elements]]
type = "Force"
name = "push"
marker = "shoe"
vector = ["10 N", 0, 0]

[solver]
t_end = "2 s"
step = { mode = "fixed", h = "1 ms" }

[output]
dt = "10 ms"
"""


@pytest.fixture(scope="module")
def cluster_client():
    """A LocalCluster of two single-threaded worker processes, shared by the module."""
    import logging

    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           host="127.0.0.1", dashboard_address="127.0.0.1:0",
                           silence_logs=logging.ERROR)
    client = Client(cluster)
    yield client
    client.close()
    cluster.close()


def _invoke(args: list[str]):
    return CliRunner().invoke(main, args, catch_exceptions=False)


# -- design -------------------------------------------------------------------------------


def test_vary_forms():
    v = parse_vary("pockets.mu=0.10:0.20:5")
    assert v.key == "pockets.mu" and v.unit == ""
    assert v.values == tuple(np.linspace(0.10, 0.20, 5))
    v = parse_vary("bench.torque=50:250:3 N m")
    assert v.values == (50.0, 150.0, 250.0) and v.model_value(150.0) == "150.0 N m"
    assert parse_vary("differentials.front=open,torsen-b").values == ("open", "torsen-b")
    assert parse_vary("solver.rho_inf=0.8,1").values == (0.8, 1.0)
    assert parse_vary("x.y=3:3:1").values == (3.0,)


@pytest.mark.parametrize("text, fragment", [
    ("pockets.mu=0.1:0.2:0", "N = 0: expected at least 1 point"),
    ("pockets.mu=0.1:0.2:2.5", "N = '2.5' is not a whole number"),
    ("pockets.mu=0.1:0.2", "expected START:STOP:N"),
    ("pockets.mu=a:0.2:3", "START: 'a' is not a number"),
    ("pockets.mu=0.1:0.1:3", "3 identical points"),
    ("pockets.mu=0.1:0.2:1", "N = 1 with START != STOP"),
    ("pockets.mu=0.1:nan:3", "not a finite number"),
    ("pockets.mu", "expected pockets.mu=START:STOP:N"),
    ("=0.1:0.2:3", "the key is empty"),
    ("pockets.mu=0.1,0.1", "a value is repeated"),
    ("pockets.mu=0.1:0.2:3 furlong", "unknown unit 'furlong'"),
])
def test_vary_errors_name_the_key(text, fragment):
    with pytest.raises(SweepInputError) as exc:
        parse_vary(text)
    assert fragment in str(exc.value) and "--vary" in str(exc.value)


def test_sample_and_metric_forms():
    s = parse_sample("pockets.mu=normal(0.17, 0.01)")
    assert (s.distribution, s.a, s.b) == ("normal", 0.17, 0.01)
    assert parse_sample("bench.torque=uniform(100,150) N m").unit == "N m"
    for bad, frag in [("pockets.mu=normal(0.17,0)", "SD > 0"),
                      ("pockets.mu=uniform(2,1)", "LOW < HIGH"),
                      ("pockets.mu=gamma(1,2)", "expected pockets.mu=normal(MEAN,SD)")]:
        with pytest.raises(SweepInputError, match=frag.replace("(", r"\(").replace(")", r"\)")):
            parse_sample(bad)
    m = parse_metric("rod.position[2]:mean@1:2.5")
    assert (m.variable, m.component, m.reducer, m.window) == ("rod.position", 2, "mean",
                                                              (1.0, 2.5))
    with pytest.raises(SweepInputError, match="unknown reducer"):
        parse_metric("rod.angle:median")
    with pytest.raises(SweepInputError, match="T0 < T1"):
        parse_metric("rod.angle:max@2:1")


def test_grid_is_a_full_factorial_with_common_random_numbers():
    d = grid([parse_vary("a.b=1:2:2"), parse_vary("c.d=x,y,z")],
             [parse_sample("e.f=normal(1,0.1)")], n_samples=4, seed=7)
    assert d.dims == ("a.b", "c.d", "sample") and d.shape == (2, 3, 4)
    assert len(d.points) == 24 and len({p.index for p in d.points}) == 24
    draws = np.random.default_rng(7).normal(1, 0.1, 4)
    for p in d.points:
        i, j, k = p.index
        assert p.overrides == {"a.b": [1.0, 2.0][i], "c.d": "xyz"[j], "e.f": float(draws[k])}
    with pytest.raises(SweepInputError, match="twice"):
        grid([parse_vary("a.b=1:2:2")], [parse_sample("a.b=normal(1,1)")], 3)


def test_sensitivity_stencil():
    d = sensitivity([("k", 1000.0, "N/m"), ("c", 2.0, "")], 0.01)
    assert d.shape == (2, 3) and len(d.points) == 5
    ov = {p.index: p.overrides for p in d.points}
    assert ov[(-1, 1)] == {"k": "1000.0 N/m", "c": 2.0}
    assert ov[(0, 0)] == {"k": "990.0 N/m", "c": 2.0}
    assert ov[(1, 2)] == {"k": "1000.0 N/m", "c": 2.02}
    with pytest.raises(SweepInputError, match="nominal value is 0"):
        sensitivity([("k", 0.0, "")], 0.01)


# -- results ------------------------------------------------------------------------------


def test_sensitivity_equals_the_exact_derivative(tmp_path):
    """Static deflection x = 1 m + F/k: the central difference with relative step h of 1/k is
    exactly -F/(k^2 (1 - h^2)); the elasticity of the deflection is -1/(1 - h^2)."""
    f = tmp_path / "spring.toml"
    f.write_text(SPRING)
    h = 0.01
    ds = sweep(f, sensitivity_keys=["elements.spring.stiffness", "elements.push.vector.0"],
               metrics=["block.position[0]:final"], rel_step=h, scheduler="serial")
    k, F = 1000.0, 10.0
    x = ds["block.position[0]:final"].values
    assert x[0, 1] == pytest.approx(1 + F / k, rel=1e-9)
    d = ds["sensitivity.block.position[0]:final"].values
    assert d[0] == pytest.approx(-F / (k * k * (1 - h * h)), rel=1e-7)  # measured 2.8e-8
    assert d[1] == pytest.approx(1 / k, rel=1e-7)  # linear in F: exact
    assert ds["nominal"].values.tolist() == [1000.0, 10.0]


def test_grid_on_a_local_cluster_equals_separate_run_commands(cluster_client, tmp_path):
    """A 2 x 3 sweep on two workers gives the same numbers, bit for bit, as six `drivedyn run`
    commands with the same --set values."""
    ds = sweep("pendulum", ["bodies.rod.mass=1:2:2", "solver.rho_inf=0.6,0.8,1.0"],
               t_end=0.3, metrics=["hinge.angle:final", "hinge.torque_y:absmax"],
               client=cluster_client)
    assert ds.sizes == {"bodies.rod.mass": 2, "solver.rho_inf": 3}
    assert set(ds["status"].values.ravel()) == {"ok"}
    assert len(set(ds["host"].values.ravel())) == 2  # both workers took points
    for i, mass in enumerate(ds["bodies.rod.mass"].values):
        for j, rho in enumerate(ds["solver.rho_inf"].values):
            r = _invoke(["run", "pendulum", "--t-end", "0.3", "--json",
                         "--set", f"bodies.rod.mass={float(mass)!r}",
                         "--set", f"solver.rho_inf={float(rho)!r}",
                         "--out", str(tmp_path / "p.nc")])
            assert r.exit_code == 0, r.output
            s = json.loads(r.stdout)
            point = ds.isel({"bodies.rod.mass": i, "solver.rho_inf": j})
            assert float(point["hinge.angle:final"]) == s["final"]["hinge.angle"]
            assert float(point["energy_balance_error"]) == s["energy_balance_error"]
            assert float(point["dissipated_energy"]) == s["dissipated_energy"]
            assert int(point["newton_iterations"]) == s["newton_iterations"]
            assert int(point["steps"]) == s["steps"]


def _listening(pid: int) -> list[tuple[str, int]]:
    """(address, port) of every TCP socket in LISTEN state held by process ``pid`` or its
    descendants (Linux: the sockets' inodes in /proc/PID/fd against /proc/net/tcp{,6})."""
    import socket

    def children(p: int) -> list[int]:
        out = []
        for q in filter(str.isdigit, os.listdir("/proc")):
            try:
                with open(f"/proc/{q}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            if ppid == p:
                out += [int(q), *children(int(q))]
        return out

    inodes = set()
    for p in (pid, *children(pid)):
        try:
            fds = os.listdir(f"/proc/{p}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                link = os.readlink(f"/proc/{p}/fd/{fd}")
            except OSError:
                continue
            if link.startswith("socket:["):
                inodes.add(link[8:-1])
    found = []
    for path, fam in (("/proc/net/tcp", socket.AF_INET), ("/proc/net/tcp6", socket.AF_INET6)):
        with open(path) as f:
            next(f)
            for line in f:
                parts = line.split()
                if parts[3] != "0A" or parts[9] not in inodes:  # 0A: LISTEN
                    continue
                addr, port = parts[1].split(":")
                raw = bytes.fromhex(addr)
                raw = b"".join(raw[i:i + 4][::-1] for i in range(0, len(raw), 4))
                found.append((socket.inet_ntop(fam, raw), int(port, 16)))
    return found


@pytest.mark.parametrize("host", [None, "0.0.0.0"])
def test_embedded_cluster_listens_on_loopback(monkeypatch, host):
    """A default sweep's own cluster (scheduler, workers, nannies, dashboard) listens on
    127.0.0.1 only, and the message names the dashboard; ``host="0.0.0.0"`` (``--host``)
    opens it on every interface. Fails with the dashboard on ":0" (all interfaces), as it
    was."""
    if not sys.platform.startswith("linux"):
        pytest.skip("reads /proc")
    from drivedyn.sweeps import execute

    seen: list = []
    submit = execute._submit

    def spy(client, tasks):
        seen.extend(_listening(os.getpid()))
        yield from submit(client, tasks)

    monkeypatch.setattr(execute, "_submit", spy)
    # its own cluster, even where a module fixture's client is the default one
    monkeypatch.setattr(execute, "_default_client", lambda: None)
    said: list[str] = []
    kw = {} if host is None else {"host": host}
    ds = sweep("pendulum", ["bodies.rod.mass=1:2:2"], t_end=0.05,
               metrics=["hinge.angle:final"], workers=2, on_cluster=said.append, **kw)
    assert set(ds["status"].values.ravel()) == {"ok"}
    addresses = {a for a, _ in seen}
    assert len(seen) >= 3  # scheduler, dashboard, the workers and nannies
    if host is None:
        assert addresses <= {"127.0.0.1", "::1"}, seen
        assert "dashboard http://127.0.0.1:" in said[0]
    else:
        assert "0.0.0.0" in addresses, seen


def test_the_callers_dask_client_is_used(cluster_client):
    """As in a notebook: with a Client made by the caller, `sweep` runs on it."""
    ds = sweep("pendulum", ["bodies.rod.mass=1,2"], t_end=0.1)
    workers = {f":{p}" for p in cluster_client.run(os.getpid).values()}
    assert {h[h.rindex(":"):] for h in ds["host"].values} <= workers


def test_tdr_sweep_equals_tdr_commands(cluster_client):
    """TDR sweeps: 2 x 3 analytic points and one simulated point equal `drivedyn tdr --json`
    with the same --set values, bit for bit."""
    ds = sweep("torsen-c", ["pockets.mu=0.15:0.19:2", "washers.ring_case.mu=0.05:0.09:3"],
               tdr=True, analytic_only=True, scheduler="serial")
    for i, a in enumerate(ds["pockets.mu"].values):
        for j, b in enumerate(ds["washers.ring_case.mu"].values):
            r = _invoke(["tdr", "torsen-c", "--analytic-only", "--json",
                         "--set", f"pockets.mu={float(a)!r}",
                         "--set", f"washers.ring_case.mu={float(b)!r}"])
            rows = json.loads(r.stdout)["modes"]
            for row in rows:
                m = row["mode"]
                assert float(ds[f"tdr.mode{m}"].values[i, j]) == row["tdr"]
    sim = sweep("torsen-c", ["pockets.mu=0.16"], tdr=True, modes=[1], client=cluster_client)
    r = _invoke(["tdr", "torsen-c", "--mode", "1", "--json", "--set", "pockets.mu=0.16"])
    out = json.loads(r.stdout)
    assert float(sim["tdr.mode1"].values[0]) == out["modes"][0]["tdr"]
    assert float(sim["analytic.mode1"].values[0]) == out["modes"][0]["analytic"]
    assert float(sim["peak_pressure"].values[0]) == out["metrics"]["peak_pressure"]
    assert float(sim["dissipated_energy"].values[0]) == out["metrics"]["dissipated_energy"]
    assert sim["peak_pressure"].attrs["units"] == "Pa"


def test_cache_resumes_and_notices_changes(tmp_path):
    f = tmp_path / "spring.toml"
    f.write_text(SPRING)
    cache = tmp_path / "cache"
    args = dict(vary=["elements.spring.stiffness=800:1200:3"], metrics=["block.position[0]:final"],
                scheduler="serial", cache=cache)
    first = sweep(f, **args)
    assert first.attrs["computed"] == 3 and len(list(cache.glob("*.json"))) == 3
    again = sweep(f, **args)
    assert again.attrs["computed"] == 0 and bool(again["cached"].all())
    name = "block.position[0]:final"
    assert np.array_equal(again[name].values, first[name].values)
    # a wider range reuses the common points
    more = sweep(f, **{**args, "vary": ["elements.spring.stiffness=800:1200:5"]})
    assert more.attrs["computed"] == 2
    # editing the model file invalidates its points
    f.write_text(SPRING.replace('"10 N"', '"20 N"'))
    edited = sweep(f, **args)
    assert edited.attrs["computed"] == 3
    assert edited[name].values[1] == pytest.approx(1 + 20 / 1000, rel=1e-9)
    assert sweep(f, **args, fresh=True).attrs["computed"] == 3


def test_cache_key_covers_the_files_a_model_names(tmp_path):
    """A vehicle's TORSEN files are part of its points' key."""
    from drivedyn.sweeps.cache import referenced_files

    refs = referenced_files(Path(__import__("drivedyn.config.loader", fromlist=["x"])
                                 .resolve_path("vehicle-4wd")))
    assert {"torsen-c", "torsen-b"} <= set(refs)
    assert "simple-dry" not in refs  # names that are not files are not hashed


def test_a_failed_point_is_a_value(tmp_path):
    ds = sweep("pendulum", ["bodies.rod.mass=-1,1"], t_end=0.1, scheduler="serial",
               cache=tmp_path / "c")
    assert ds["status"].values.tolist() == ["invalid", "ok"]
    assert "bodies" in str(ds["message"].values[0]) and "mass" in str(ds["message"].values[0])
    assert np.isnan(ds["dissipated_energy"].values[0])
    assert np.isfinite(ds["dissipated_energy"].values[1])
    again = sweep("pendulum", ["bodies.rod.mass=-1,1"], t_end=0.1, scheduler="serial",
                  cache=tmp_path / "c")
    assert again.attrs["computed"] == 0  # an invalid point is a result: not retried


def test_interrupted_sweep_keeps_finished_points(tmp_path):
    cache = tmp_path / "c"
    calls = []

    def progress(done, total, rec, cached):
        calls.append(done)
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted) as exc:
        sweep("pendulum", ["bodies.rod.mass=1:2:4"], t_end=0.1, scheduler="serial",
              cache=cache, progress=progress)
    part = exc.value.dataset
    assert part["status"].values.tolist() == ["ok", "ok", "missing", "missing"]
    assert np.isnan(part["dissipated_energy"].values[2:]).all()
    rest = sweep("pendulum", ["bodies.rod.mass=1:2:4"], t_end=0.1, scheduler="serial",
                 cache=cache)
    assert rest.attrs["computed"] == 2 and set(rest["status"].values) == {"ok"}


def test_killing_a_worker_loses_no_finished_point(tmp_path):
    """A worker killed in the middle of a sweep: the points it had finished are kept, its
    point comes back `lost` (retries off here to see it), and the rerun computes only that."""
    import logging

    import dask
    from distributed import Client, LocalCluster

    cache = tmp_path / "c"
    vary = ["bodies.rod.mass=1:2:6"]
    killed = []
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                               dashboard_address=":0", silence_logs=logging.CRITICAL)
        client = Client(cluster)
        try:
            pids = client.run(os.getpid)

            def progress(done, total, rec, cached):
                if not killed:  # both workers are busy with the next points
                    pid = next(p for a, p in pids.items() if not rec["host"].endswith(
                        f":{p}"))
                    os.kill(pid, signal.SIGKILL)
                    killed.append(pid)

            ds = sweep("pendulum", vary, t_end=6.0, client=client, cache=cache,
                       progress=progress)
        finally:
            client.close()
            cluster.close()
    status = ds["status"].values.tolist()
    assert killed and status.count("lost") >= 1, status
    assert status.count("ok") + status.count("lost") == 6
    assert len(list(cache.glob("*.json"))) == status.count("ok")
    rerun = sweep("pendulum", vary, t_end=6.0, scheduler="serial", cache=cache)
    assert rerun.attrs["computed"] == status.count("lost")
    assert set(rerun["status"].values) == {"ok"}
    full = sweep("pendulum", vary, t_end=6.0, scheduler="serial")
    assert np.array_equal(rerun["dissipated_energy"].values, full["dissipated_energy"].values)
    assert np.array_equal(rerun["newton_iterations"].values, full["newton_iterations"].values)


def test_external_scheduler_and_worker(tmp_path):
    """`dask scheduler` and `dask worker` started as separate processes on localhost."""
    sched_file = tmp_path / "scheduler.json"
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host",
                               "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(sched_file)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)]
    try:
        t0 = time.time()
        while not sched_file.exists() and time.time() - t0 < 60:
            time.sleep(0.2)
        address = json.loads(sched_file.read_text())["address"]
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "dask", "worker", address, "--nthreads", "1",
             "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env=env))
        out = tmp_path / "s.nc"
        r = CliRunner().invoke(main, [
            "sweep", "pendulum", "--vary", "bodies.rod.mass=1:2:3", "--t-end", "0.2",
            "--metric", "hinge.angle:final", "--scheduler", address, "--out", str(out),
            "--json"], catch_exceptions=False)
        assert r.exit_code == 0, r.output
        assert json.loads(r.stdout)["status_counts"]["ok"] == 3
        import xarray as xr

        with xr.open_dataset(out) as ds:
            remote = ds["hinge.angle:final"].values
            hosts = set(ds["host"].values)
        local = sweep("pendulum", ["bodies.rod.mass=1:2:3"], t_end=0.2,
                      metrics=["hinge.angle:final"], scheduler="serial")
        assert np.array_equal(remote, local["hinge.angle:final"].values)
        assert len(hosts) == 1 and f":{os.getpid()}" not in hosts.pop()
    finally:
        for p in procs[::-1]:
            p.terminate()
            p.wait(timeout=30)


def test_monte_carlo_statistics():
    ds = sweep("torsen-c", sample=["pockets.mu=normal(0.173,0.005)"], samples=64, seed=3,
               tdr=True, analytic_only=True, modes=[1], scheduler="serial")
    mu = ds["pockets.mu"].values
    assert np.array_equal(mu, np.random.default_rng(3).normal(0.173, 0.005, 64))
    x = ds["tdr.mode1"].values
    assert float(ds["mean.tdr.mode1"]) == pytest.approx(x.mean(), rel=1e-12)
    assert float(ds["std.tdr.mode1"]) == pytest.approx(x.std(ddof=1), rel=1e-12)
    assert ds["quantiles.tdr.mode1"].values == pytest.approx(
        np.quantile(x, [0.05, 0.25, 0.5, 0.75, 0.95]), rel=1e-12)
    # the TDR rises with the pocket friction: draws and outputs are ranked alike
    assert np.array_equal(np.argsort(mu), np.argsort(x))


# -- command line -------------------------------------------------------------------------


@pytest.mark.parametrize("args, fragment", [
    (["--vary", "pockets.muu=0.1:0.2:3"], "--vary pockets.muu: torsen-c has no key "
     "'pockets.muu' (did you mean 'mu'?)"),
    (["--vary", "pockets.mu=0.1:0.2:0"], "N = 0: expected at least 1 point"),
    (["--vary", "pockets.mu=0.2:0.1"], "expected START:STOP:N"),
    (["--vary", "bodies.x.mass=1:2:2"], "--vary bodies.x.mass"),
    (["--sample", "pockets.mu=normal(0.1,0.01)"], "--sample needs --samples N"),
    (["--vary", "pockets.mu=0.1:0.2:2", "--metric", "rod.angle"], "go with scenario runs"),
    (["--vary", "pockets.mu=0.1:0.2:2", "--mode", "5"], "--mode '5'"),
    (["--sensitivity", "--vary", "pockets.mu=0.1:0.2:3"], "with --sensitivity give"),
])
def test_bad_sweep_input_exits_2(args, fragment):
    r = CliRunner().invoke(main, ["sweep", "torsen-c", "--tdr", "--analytic-only",
                                  "--scheduler", "serial", "--no-cache", *args])
    assert r.exit_code == 2, r.output
    assert fragment in r.output
    assert "Traceback" not in r.output


def test_bad_input_of_scenario_sweeps_exits_2(tmp_path):
    for args, fragment in [
        (["pendulum", "--vary", "bodies.rod.mass=1:2:2", "--metric", "rod.angle:max"],
         "no variable 'rod.angle'"),
        (["pendulum", "--tdr", "--vary", "bodies.rod.mass=1:2:2"],
         "not a differential model file"),
        (["pendulum", "--vary", "elements.hinge.kk=1:2:2"],
         "--vary elements.hinge.kk: pendulum has no key 'elements.kk' (did you mean 'k'?)"),
        (["pendulum", "--vary", "bodies.rod.mass=1:2:2", "--set", "elements.hinge.k=-1"],
         "elements[0] (hinge).k: must be > 0"),
        (["pendulum", "--vary", "bodies.rod.mass=1:2:2", "--scheduler",
          "tcp://127.0.0.1:9", "--connect-timeout", "1"], "cannot connect"),
    ]:
        r = CliRunner().invoke(main, ["sweep", *args, "--out", str(tmp_path / "x.nc")])
        assert r.exit_code == 2, r.output
        assert fragment in r.output
    assert not (tmp_path / "x.nc").exists()


def test_cli_sweep_writes_results_and_figures(tmp_path):
    out = tmp_path / "map.nc"
    r = _invoke(["sweep", "torsen-c", "--tdr", "--analytic-only", "--mode", "1,3",
                 "--vary", "pockets.mu=0.15:0.19:3", "--vary", "washers.ring_case.mu=0.05,0.09",
                 "--scheduler", "serial", "--out", str(out), "--plots", str(tmp_path / "f")])
    assert r.exit_code == 0, r.output
    assert "6 points (6 ok)" in r.output and "6 computed, 0 from the cache" in r.output
    assert {p.name for p in (tmp_path / "f").iterdir()} == {"heatmap.png", "lines.png"}
    assert (tmp_path / "map.nc.cache").is_dir()
    r = _invoke(["sweep", "torsen-c", "--tdr", "--analytic-only", "--mode", "1,3",
                 "--vary", "pockets.mu=0.15:0.19:3", "--vary", "washers.ring_case.mu=0.05,0.09",
                 "--scheduler", "serial", "--out", str(out)])
    assert "0 computed, 6 from the cache" in r.output
    r = _invoke(["plot", str(out), "--out", str(tmp_path / "g")])
    assert r.exit_code == 0 and "heatmap.png" in r.output


def test_sweep_figures_draw_the_outputs(tmp_path):
    from drivedyn.plots.sweeps import heatmap_figure, lines_figure, plot_sweep, tornado_figure

    ds = sweep("torsen-c", ["pockets.mu=0.15:0.19:3", "washers.ring_case.mu=0.05,0.07"],
               tdr=True, analytic_only=True, modes=[1], scheduler="serial")
    fig = lines_figure(ds)
    ax = fig.axes[0]
    assert ax.get_ylabel() == "tdr.mode1"
    y = np.vstack([ln.get_ydata() for ln in ax.lines if ln.get_marker() == "o"])
    assert np.array_equal(y, ds["tdr.mode1"].values.T)
    hm = heatmap_figure(ds)
    assert np.array_equal(np.asarray(hm.axes[0].images[0].get_array()),
                          ds["tdr.mode1"].transpose("washers.ring_case.mu", "pockets.mu").values)
    sens = sweep("torsen-c", sensitivity_keys=["pockets.mu", "washers.ring_case.mu"],
                 tdr=True, analytic_only=True, modes=[1], scheduler="serial")
    tor = tornado_figure(sens)
    widths = sorted(p.get_width() for p in tor.axes[0].patches)
    assert widths == sorted(sens["elasticity.tdr.mode1"].values.tolist())
    assert [p.name for p in plot_sweep(sens, tmp_path)] == ["tornado.png"]
