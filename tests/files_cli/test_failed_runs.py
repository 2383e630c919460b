"""Runs that cannot continue keep their results; files are written atomically; the same
command twice gives bit-identical result arrays.

The failing run is the shipped bouncing ball with one Newton iteration allowed and a
1e-12 tolerance: the first step that reaches the floor cannot converge at any step size,
so the run stops at the impact time sqrt(2 h0 / g) = sqrt(0.2) s, naming the ball's
vertical equation.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.results import load_results
from drivedyn.results.results import _write_atomic

FAILING = ["--set", "solver.newton.max_iter=1", "--set", "solver.newton.tol=1e-12",
           "--set", 'solver.step={mode="fixed", h="1 ms"}']


def test_failed_run_exit_1_message_and_partial_results(tmp_path: Path) -> None:
    out = tmp_path / "bb.nc"
    res = CliRunner().invoke(main, ["run", "bouncing_ball", "--out", str(out), *FAILING])
    text = res.output + res.stderr
    assert res.exit_code == 1, text
    assert "Traceback" not in text
    t_impact = math.sqrt(2 * 1.0 / 10.0)
    assert f"stopped at t = {t_impact:.4f}" in text
    assert "worst equation: node ball: uz" in text          # the dof with the residual
    assert "try a smaller step" in text                     # what to do about it
    partial = tmp_path / "bb.partial.nc"
    assert partial.exists() and not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bb.partial.nc"]  # no temporaries
    ds = xr.load_dataset(partial)
    assert ds.attrs["success"] == 0 and "stopped at" in ds.attrs["message"]
    assert abs(float(ds["time"][-1]) - t_impact) < 2e-3
    z = ds["ball.position"].values[:, 2]
    assert np.all(np.isfinite(z)) and z[0] == pytest.approx(1.0)
    assert not load_results(partial).success


def test_atomic_write_leaves_nothing_on_failure(tmp_path: Path) -> None:
    target = tmp_path / "r.nc"

    def half_then_crash(tmp: str) -> None:
        Path(tmp).write_bytes(b"half a file")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        _write_atomic(target, half_then_crash)
    assert list(tmp_path.iterdir()) == []
    target.write_text("old results")
    with pytest.raises(OSError):
        _write_atomic(target, half_then_crash)
    assert target.read_text() == "old results"          # the previous file is untouched
    assert [p.name for p in tmp_path.iterdir()] == ["r.nc"]


@pytest.mark.parametrize("model, extra", [("bouncing_ball", ["--set", "solver.t_end=0.6"]),
                                          ("slider_crank", ["--t-end", "0.3"])])
def test_same_command_twice_is_bit_identical(tmp_path: Path, model: str,
                                             extra: list[str]) -> None:
    paths = [tmp_path / f"a{i}.nc" for i in range(2)]
    for p in paths:
        res = CliRunner().invoke(main, ["run", model, "--out", str(p), *extra])
        assert res.exit_code == 0, res.output + res.stderr
    a, b = (xr.load_dataset(p) for p in paths)
    assert list(a.data_vars) == list(b.data_vars) and len(a.data_vars) > 10
    for name in a.data_vars:
        va, vb = a[name].values, b[name].values
        assert va.dtype == vb.dtype and va.shape == vb.shape, name
        assert va.tobytes() == vb.tobytes(), f"{name} differs between two identical runs"
    assert a["time"].values.tobytes() == b["time"].values.tobytes()


@pytest.mark.parametrize("path", ["record", "extend"])
def test_ctrl_c_within_a_snapshot_keeps_consistent_partial_results(monkeypatch, path) -> None:
    """A KeyboardInterrupt can arrive between two appends of Recorder.record (a cold
    `drivedyn run` interrupted at an output time wrote no partial file: "cannot reshape array
    of size 35 into shape (6, 7)"), or of Recorder.extend (the compiled loop's batches of
    outputs, here one output each after a first batch of four). The incomplete snapshot is
    dropped and the state reached is recorded whole."""
    import drivedyn as dd
    from drivedyn.results.recorder import Recorder
    from drivedyn.solver import step_loop

    calls = {"n": 0}
    record, extend = Recorder.record, Recorder.extend

    def interrupted(self, st, h=0.0):
        calls["n"] += 1
        if calls["n"] == 6:  # half a snapshot, then Ctrl-C
            self.t.append(st.t)
            self.x.append(st.x[: self.model.nn].copy())
            raise KeyboardInterrupt
        record(self, st, h)

    def interrupted_batch(self, t, x, *rest):
        calls["n"] += 1
        if calls["n"] == 2:  # half a snapshot of the second batch, then Ctrl-C
            self.t.append(float(t[0]))
            self.x.append(x[0])
            raise KeyboardInterrupt
        extend(self, t, x, *rest)

    if path == "record":
        monkeypatch.setattr(Recorder, "extendable", property(lambda self: False))
        monkeypatch.setattr(Recorder, "record", interrupted)
    else:
        monkeypatch.setattr(step_loop, "BATCH_WALL", 0.0)
        monkeypatch.setattr(Recorder, "extend", interrupted_batch)
    res = dd.simulate(dd.load_model("pendulum"), 1.0, output_dt=0.01)
    assert not res.success and "interrupted by the user" in res.message
    ds = res.dataset
    assert ds.sizes["time"] == 6  # five whole snapshots and the state reached, recorded whole
    assert np.all(np.diff(res.time) > 0)
    for name in ds.data_vars:
        assert np.all(np.isfinite(ds[name].values)), name
