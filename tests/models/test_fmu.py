"""FMUs of the TORSEN differentials (``drivedyn fmu``) run by FMPy: the FMU validates; driven
with the bench's inputs it gives the TDRs of ``drivedyn tdr`` for the four modes of both
TORSENs; halving the communication step leaves the steady torques unchanged; a NaN or
infinite input is an error status with its reason in the log, not a crash; two instances of
one model run side by side in one process; without drivedyn the FMU refuses to instantiate
with a message that says to install it; the command refuses bad input with exit code 2. The
4WD vehicle's FMU gives the wheel torques of the library's run and follows its road-friction
inputs; the RWD vehicle's FMU, from its static start, gives the drive torques of the library's
run and refuses a NaN or out-of-range throttle with an error status.

The bench runs the shorter protocol of ``examples/08_torsen_b.py`` (the same torque and
speed difference, 1.1 s per side), in the FMU and in ``drivedyn tdr`` alike.
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")
pytest.importorskip("fmpy.validation")

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from drivedyn.analysis.tdr import run_bench  # noqa: E402
from drivedyn.cli import main  # noqa: E402
from drivedyn.config import read_library_file  # noqa: E402
from drivedyn.fmu import build_fmu  # noqa: E402
from drivedyn.fmu.bench import bench_inputs, window_tdrs  # noqa: E402
from drivedyn.library import differentials  # noqa: E402
from fmu_helpers import Instance  # noqa: E402

SHORT = ["bench.ramp=0.1", "bench.transition=[0.5, 0.8]", "bench.t_end=1.1",
         "bench.window_drive=[0.25, 0.45]", "bench.window_coast=[0.9, 1.1]"]
MODELS = ("torsen-b", "torsen-c")
FMI2_DISCARD = 2


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    """model name -> its FMU (built with the short bench protocol's overrides)."""
    folder = tmp_path_factory.mktemp("fmus")
    return {m: build_fmu(m, folder / f"{m.replace('-', '_')}.fmu", SHORT) for m in MODELS}


_RUNS: dict[tuple, np.ndarray] = {}


def _bench_fmu(fmus, model: str, side: str, dt: float, stop: float | None = None):
    """FMPy's run of the FMU of ``model`` with the bench inputs of ``side`` held over
    communication steps of ``dt`` [s] (kept for the other tests)."""
    key = (model, side, dt, stop)
    if key not in _RUNS:
        p = read_library_file(model, SHORT)[0]
        _RUNS[key] = fmpy.simulate_fmu(
            str(fmus[model]), start_time=0.0, stop_time=stop or p.bench.t_end, step_size=dt,
            output_interval=dt, input=bench_inputs(p, side, dt))
    return _RUNS[key]


def test_the_fmus_validate(fmus) -> None:
    """FMPy's validation finds nothing (units defined, initial unknowns listed). Made to fail
    by dropping the InitialUnknowns of DrivedynSlave.to_xml."""
    for path in fmus.values():
        assert validate_fmu(str(path)) == []


@pytest.mark.slow
@pytest.mark.parametrize("model", MODELS)
def test_the_bench_through_the_fmu_gives_the_tdr_of_drivedyn_tdr(fmus, model) -> None:
    """Each of the four modes within 1 % of ``drivedyn tdr``'s bench (measured: within
    0.01 %). Made to fail by hold_value forgetting the integral of the held speed (the
    output angles then jump back at each communication point) or by the speed drivers
    turning the outputs the other way (cosim_spec with -w: the other modes)."""
    p = read_library_file(model, SHORT)[0]
    diff = differentials.of(p)
    for side in diff.sides:
        res = _bench_fmu(fmus, model, side, 1e-3)
        assert res["time"][-1] == pytest.approx(p.bench.t_end)
        fmu = window_tdrs(p, side, res["time"], {n: res[n] for n in res.dtype.names})
        ref = run_bench(p, side).tdr
        for mode, tdr in ref.items():
            assert fmu[mode] == pytest.approx(tdr, rel=1e-2), (model, mode)


@pytest.mark.slow
def test_halving_the_communication_step_leaves_the_steady_torques(fmus) -> None:
    """The drive window's mean torques at 1 ms and 0.5 ms communication steps within 0.1 %
    (measured: 2e-6). Made to fail by holding each input only for the first step inside
    the FMU (advance in two halves with the input reset to 0 for the second)."""
    p = read_library_file("torsen-b", SHORT)[0]
    a, b = p.bench.window_drive
    means = []
    for dt in (1e-3, 5e-4):
        res = _bench_fmu(fmus, "torsen-b", "right", dt, stop=b)
        k = (res["time"] >= a) & (res["time"] <= b)
        means.append(np.array([res["left_torque"][k].mean(), res["right_torque"][k].mean()]))
    assert np.all(np.abs(means[1] / means[0] - 1) < 1e-3), means


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_input_is_an_error_status_with_its_reason(fmus, bad) -> None:
    """doStep answers fmi2Discard (the FMU asks to terminate) and logs why at error level;
    the FMU is still there to be asked (its outputs are those of the last good step). Made
    to fail by DifferentialCosim.step passing the inputs on unchecked (the solver then
    fails later, or the run goes on with NaN)."""
    inst = Instance(fmus["torsen-b"], "bad")
    try:
        inst.start({"input_torque": 10.0})
        inst.step(0.0, 1e-3)
        before = inst.get("left_torque", "right_torque")
        inst.set({"left_speed": bad})
        with pytest.raises(FMICallException) as exc:
            inst.step(1e-3, 1e-3)
        assert exc.value.status == FMI2_DISCARD
        assert any(status == 3 and "non-finite input" in text and "left_speed" in text
                   for status, text in inst.messages), inst.messages
        assert inst.get("left_torque", "right_torque") == before
    finally:
        inst.close()


def test_a_solver_failure_is_an_error_status_with_its_reason(fmus) -> None:
    """An imposed speed that steps to 1e5 rad/s: the solver stops at its smallest step,
    doStep answers fmi2Discard and the log says where and why at error level. Made to fail
    by DrivedynSlave.do_step raising on a failed step (fmi2Fatal, the instance gone)."""
    inst = Instance(fmus["torsen-b"], "fails")
    try:
        inst.start()
        inst.step(0.0, 1e-3)
        inst.set({"left_speed": 1e5})
        with pytest.raises(FMICallException) as exc:
            inst.step(1e-3, 1e-3)
        assert exc.value.status == FMI2_DISCARD
        assert any(status == 3 and "simulation stopped at t = 0.001 s" in text
                   for status, text in inst.messages), inst.messages
    finally:
        inst.close()


def _drive(inst: Instance, torque: float) -> list[float]:
    """One 1 ms step of ``inst`` with ``torque`` [N m] on the housing: the output torques."""
    inst.set({"input_torque": torque})
    inst.step(inst.t, 1e-3)
    return inst.get("left_torque", "right_torque")


def test_two_instances_of_one_model_in_one_process(fmus) -> None:
    """Two instances stepped in turn with opposite housing torques give, step for step, the
    output torques each gives alone (each has its own compiled model and state). Made to
    fail by DifferentialCosim keeping its Simulation in a class attribute (shared)."""
    from fmpy import extract

    path = fmus["torsen-b"]
    unzipdir = extract(str(path))
    both: dict[float, list] = {100.0: [], -100.0: []}
    pair = {100.0: Instance(path, "a", unzipdir), -100.0: Instance(path, "b", unzipdir)}
    try:
        for inst in pair.values():
            inst.start()
        for _ in range(40):
            for torque, inst in pair.items():
                both[torque].append(_drive(inst, torque))
    finally:
        for inst in pair.values():
            inst.close()
    for torque, series in both.items():
        alone = Instance(path, f"alone{torque:+.0f}")
        try:
            alone.start()
            assert [_drive(alone, torque) for _ in range(40)] == series
        finally:
            alone.close()
    assert min(both[100.0][-1]) > 10 and max(both[-100.0][-1]) < -10


def test_an_fmu_without_drivedyn_says_to_install_it(fmus) -> None:
    """In a Python that cannot import drivedyn the FMU does not instantiate, and its log
    says that it runs drivedyn and how to install it. Made to fail by the generated script
    importing drivedyn without its ImportError message."""
    script = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {str(Path(__file__).parents[1])!r})
        from fmu_helpers import Instance
        sys.modules["drivedyn"] = None  # as if it were not installed
        try:
            Instance({str(fmus["torsen-b"])!r}, "x")
        except Exception:
            pass
        import fmu_helpers
        print("\\n".join(m for _, m in fmu_helpers.LAST_MESSAGES))
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300)
    log = proc.stdout + proc.stderr
    assert "runs drivedyn" in log and "pip install 'drivedyn[fmu]'" in log, log


@pytest.mark.parametrize(("args", "says"), [
    (["nosuch"], "nosuch"),
    (["pendulum"], "no FMU interface"),
    (["bouncing_ball"], "no FMU interface"),
    (["torsen-b", "--set", "pockets.muu=0.1"], "pockets.muu"),
    (["torsen-b", "--out", "x.zip"], "--out"),
    (["torsen-b", "--out", "{file}/x.fmu"], "--out"),
])
def test_bad_input_exits_with_2_naming_it(runner, tmp_path, args, says) -> None:
    """Unknown model, a model without an FMU interface, an unknown key, an output that is not
    an .fmu or cannot be written: exit 2 and a message naming it; no FMU is written. Made to
    fail by dropping check_output_path from the command (the build then fails late)."""
    (tmp_path / "file").write_text("")
    args = [a.replace("{file}", str(tmp_path / "file")) for a in args]
    if "--out" not in args:
        args += ["--out", str(tmp_path / "x.fmu")]
    res = runner.invoke(main, ["fmu", *args])
    assert res.exit_code == 2, res.output
    assert says in res.output
    assert not (tmp_path / "x.fmu").exists()


def test_the_command_writes_the_fmu_and_lists_its_variables(runner, tmp_path) -> None:
    """``drivedyn fmu torsen-c`` writes the FMU named by --out with the Type C's variables
    and the --set value as the parameter's start. Made to fail by the builder ignoring
    --set."""
    out = tmp_path / "centre diff.fmu"
    res = runner.invoke(main, ["fmu", "torsen-c", "--out", str(out), "--set",
                               "pockets.mu=0.15"])
    assert res.exit_code == 0, res.output
    assert "front_speed [rad/s]" in res.output and "pockets.mu [1]" in res.output
    md = fmpy.read_model_description(str(out))
    assert md.coSimulation.modelIdentifier == "centre_diff"
    v = {x.name: x for x in md.modelVariables}
    assert float(v["pockets.mu"].start) == 0.15
    assert v["front_torque"].unit == "N.m" and v["rear_speed"].causality == "input"


def _vehicle_inputs(p, t_end: float, mu: float | None = None) -> np.ndarray:
    """The file's engine torque ramp (and, with ``mu``, one friction factor under every
    wheel) sampled every 1 ms."""
    t = np.arange(0.0, t_end + 5e-4, 1e-3)
    names = ["engine_torque"] + ([] if mu is None else [f"mu_{w}" for w in
                                                         ("fl", "fr", "rl", "rr")])
    out = np.zeros(t.size, dtype=[("time", float)] + [(n, float) for n in names])
    f = np.clip((t - p.load.start) / p.load.ramp, 0.0, 1.0)
    out["time"] = t
    out["engine_torque"] = p.load.torque * f * f * (3.0 - 2.0 * f)
    for n in names[1:]:
        out[n] = mu
    return out


@pytest.mark.slow
def test_the_vehicle_fmu_gives_the_wheel_torques_of_drivedyn_run(tmp_path) -> None:
    """The vehicle-4wd FMU with the file's engine ramp gives the four wheels' drive torques of
    the library's run within 1 % over the last 0.1 s of a 0.5 s launch (measured: 5e-5 over
    1 s) and the car's speed; with the same friction under every wheel its rear axle's torques
    come out even instead of biased to the grip. Made to fail by VehicleCosim not writing
    the friction factors into the tyres (the split-mu bias stays)."""
    from drivedyn.analysis.vehicle_4wd import run
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path

    path = build_fmu("vehicle-4wd", tmp_path / "vehicle.fmu")
    assert validate_fmu(str(path)) == []
    p, _, source = read_library_file("vehicle-4wd")
    t_end = 0.5
    res = fmpy.simulate_fmu(str(path), stop_time=t_end, step_size=1e-3,
                            output_interval=1e-3, input=_vehicle_inputs(p, t_end))
    base = resolve_path("vehicle-4wd").parent
    ref, lay = run(p, read_vehicle_differentials(p, source, base), base, t_end=t_end)
    k, kf = ref.values("time") >= t_end - 0.1, res["time"] >= t_end - 0.1
    for w in ("fl", "fr", "rl", "rr"):
        want = -ref.values(f"{lay.halfshafts[w]}.torque")[k].mean()
        assert res[f"torque_{w}"][kf].mean() == pytest.approx(want, rel=1e-2), w
    assert res["vehicle_speed"][-1] == pytest.approx(ref.values("body.velocity")[-1, 0],
                                                     rel=1e-2)
    assert res["torque_rr"][kf].mean() / res["torque_rl"][kf].mean() > 1.3
    even = fmpy.simulate_fmu(str(path), stop_time=t_end, step_size=1e-3,
                             output_interval=1e-3, input=_vehicle_inputs(p, t_end, mu=0.8))
    ratio = even["torque_rr"][kf].mean() / even["torque_rl"][kf].mean()
    assert abs(ratio - 1) < 0.05, ratio


#: the RWD vehicle with the open differential (the fastest to step, ~640 steps per second)
RWD_OPEN = {"differentials.rear": "open"}


@pytest.fixture(scope="module")
def rwd_fmu(tmp_path_factory) -> Path:
    """The vehicle-rwd FMU with the open rear differential."""
    return build_fmu("vehicle-rwd", tmp_path_factory.mktemp("rwd") / "vehicle_rwd.fmu",
                     RWD_OPEN)


def test_the_rwd_vehicle_fmu_gives_the_drive_torques_of_drivedyn_run(rwd_fmu) -> None:
    """The vehicle-rwd FMU, its throttle held at the file's value after the ramp (0.1) over
    0.5 s from the static start, gives the rear drive torques of the library's run with that
    throttle from t = 0 (``engine.idle_throttle`` = ``engine.throttle``) within 1e-3 at the
    end (measured: 1e-16 with the run landing on the same 1 ms points; 1.2e-3 where it
    records every 5 ms, its steps then fall elsewhere), and its speed, tyre loads and yaw
    rate. Made to fail by VehicleRWDCosim starting from the built state instead of
    static_start (the frame springs back: the drive torques 4 % off at 0.5 s)."""
    from drivedyn.analysis.vehicle_rwd import drive_torque, run
    from drivedyn.config.loader import read_vehicle_differentials, resolve_path

    assert validate_fmu(str(rwd_fmu)) == []
    md = fmpy.read_model_description(str(rwd_fmu))
    v = {x.name: x for x in md.modelVariables}
    assert v["throttle"].causality == "input" and float(v["throttle"].start) == 0.1
    assert v["torque_rl"].unit == "N.m" and v["yaw_rate"].unit == "rad/s"
    t_end = 0.5
    res = fmpy.simulate_fmu(str(rwd_fmu), stop_time=t_end, step_size=1e-3,
                            output_interval=1e-3, start_values={"throttle": 0.1})
    assert res["time"][-1] == pytest.approx(t_end)
    p, _, source = read_library_file("vehicle-rwd", {**RWD_OPEN, "engine.idle_throttle": 0.1})
    base = resolve_path("vehicle-rwd").parent
    ref, lay = run(p, read_vehicle_differentials(p, source, base), base, t_end=t_end,
                   output_dt=1e-3)
    for w in ("rl", "rr"):
        want = drive_torque(ref, lay, w)[-1]
        assert want > 100.0
        assert res[f"torque_{w}"][-1] == pytest.approx(want, rel=1e-3), w
        assert res[f"fz_{w}"][-1] == pytest.approx(ref.values(f"tyre_{w}.fz")[-1], rel=1e-3)
        assert res[f"speed_{w}"][-1] == pytest.approx(ref.values(f"tyre_{w}.spin")[-1],
                                                      rel=1e-3)
    assert res["vehicle_speed"][-1] == pytest.approx(ref.values("carrier.velocity")[-1, 0],
                                                     rel=1e-3)
    assert res["yaw_rate"][-1] == pytest.approx(ref.values("carrier.angular_velocity")[-1, 2],
                                                abs=1e-6)
    # the static start: at t = 0 the loads are the parked vehicle's, no spring-back
    assert sum(res[f"fz_{w}"][0] for w in ("fl", "fr", "rl", "rr")) == pytest.approx(
        sum(ref.values(f"tyre_{w}.fz")[0] for w in ("fl", "fr", "rl", "rr")), rel=1e-6)


@pytest.mark.parametrize(("throttle", "says"), [(math.nan, "non-finite input"),
                                                (1.5, "throttle = 1.5: expected 0 to 1")])
def test_a_bad_throttle_is_an_error_status_with_its_reason(rwd_fmu, throttle, says) -> None:
    """A NaN throttle (or one above 1) at a step: fmi2Discard, the reason in the log at
    error level, the outputs of the last good step kept. Made to fail by
    VehicleRWDCosim._check not checking the throttle's range."""
    inst = Instance(rwd_fmu, "bad")
    try:
        inst.start()
        inst.step(0.0, 1e-3)
        before = inst.get("torque_rl", "torque_rr")
        inst.set({"throttle": throttle})
        with pytest.raises(FMICallException) as exc:
            inst.step(1e-3, 1e-3)
        assert exc.value.status == FMI2_DISCARD
        assert any(status == 3 and says in text and "throttle" in text
                   for status, text in inst.messages), inst.messages
        assert inst.get("torque_rl", "torque_rr") == before
    finally:
        inst.close()
