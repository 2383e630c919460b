"""Model files, `--set` overrides and the `run`/`plot`/`models` commands, through the real
entry point (subprocess) where exit codes and messages matter."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import drivedyn as dd
from drivedyn import units as U  # noqa: N812
from drivedyn.config import ModelFileError, load_model, shipped_models
from drivedyn.units import UnitError, to_si

BLOCK = """
[model]
name = "block"
description = "block on a spring"

[[bodies]]
name = "block"
mass = "2 kg"
inertia = [0.1, 0.1, 0.1]
position = [0, 0, "1.1 m"]

[[markers]]
name = "rail"
body = "ground"
position = [0, 0, 1.1]
axis = [0, 0, 1]

[[markers]]
name = "slider"
body = "block"
axis = [0, 0, 1]

[[markers]]
name = "anchor"
body = "ground"

[[elements]]
type = "Prismatic"
name = "p"
marker_a = "rail"
marker_b = "slider"

[[elements]]
type = "SpringDamper"
name = "s"
marker_a = "anchor"
marker_b = "slider"
stiffness = "200 N/m"
free_length = "1 m"

[solver]
t_end = "0.5 s"
step = { mode = "fixed", h = "1 ms" }

[output]
dt = "0.1 s"
"""


def _write(tmp_path: Path, text: str, name: str = "m.toml") -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def _cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "drivedyn.cli", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=600)


# -- units ---------------------------------------------------------------------------------


@pytest.mark.parametrize(("text", "dim", "si"), [
    ("3 mm", U.LENGTH, 3e-3), ("1500 rpm", U.ANGULAR_VELOCITY, 1500 * 2 * np.pi / 60),
    ("2.5 kg m^2", U.INERTIA, 2.5), ("10 N m/rad", U.TORSIONAL_STIFFNESS, 10.0),
    ("90 deg", U.ANGLE, np.pi / 2), ("1e3 N s/m", U.DAMPING, 1e3), ("9.81 m/s^2",
                                                                      U.ACCELERATION, 9.81),
    (4, U.FORCE, 4.0), ("2 kN", U.FORCE, 2000.0), ("5 Nm", U.TORQUE, 5.0),
])
def test_units_convert_to_si(text, dim, si):
    assert to_si(text, dim) == pytest.approx(si, rel=1e-15)


def test_unit_errors():
    with pytest.raises(UnitError, match="unknown unit 'kgg'"):
        to_si("2 kgg", U.MASS)
    with pytest.raises(UnitError, match="'3 mm' is in m, expected kg"):
        to_si("3 mm", U.MASS)


# -- loading and validation -------------------------------------------------------------------


@pytest.mark.slow  # every shipped model file built and run: 40 s warm, 160 s cold
def test_shipped_models_load_and_run():
    assert {"pendulum", "slider_crank"} <= set(shipped_models())
    for name in shipped_models():
        model = load_model(name)
        res = dd.simulate(model, 0.05)
        assert res.success, (name, res.message)


def test_file_model_matches_python_model(tmp_path):
    """The block of the file is the oscillator of test_solver: x(t) = 0.1 cos(10 t)."""
    model = load_model(_write(tmp_path, BLOCK))
    res = dd.simulate(model)  # the file's scenario: 0.5 s at 1 ms, outputs every 0.1 s
    assert res.time[-1] == pytest.approx(0.5)
    assert len(res.time) == 6
    z = res["block.position"].values[:, 2] - 1.0
    np.testing.assert_allclose(z, 0.1 * np.cos(10 * res.time), atol=3e-4 * 0.1 * 10)


@pytest.mark.parametrize(("edit", "message"), [
    (('mass = "2 kg"', 'mass = "heavy"'),
     "bodies[0] (block).mass: expected '<number> <unit>' [kg], got 'heavy' (got 'heavy')"),
    (('mass = "2 kg"', 'mass = "2 kgg"'), "bodies[0] (block).mass: unknown unit 'kgg'"),
    (('mass = "2 kg"', "mass = -1"), "bodies[0] (block).mass: must be > 0 kg (got -1)"),
    (('inertia = [0.1, 0.1, 0.1]\n', ""), "bodies[0] (block).inertia: required key is missing"),
    (('stiffness = "200 N/m"', 'stifness = "200 N/m"'),
     "elements[1] (s).stifness: unknown key (did you mean 'stiffness'?)"),
    (('stiffness = "200 N/m"', 'stiffness = "200 N m"'),
     "elements[1] (s).stiffness: '200 N m' is in N m, expected N/m"),
    (('stiffness = "200 N/m"', "stiffness = -200"),
     "elements[1] (s).stiffness: must be >= 0 N/m, got -200.0"),
    (('type = "Prismatic"', 'type = "Slider"'),
     "elements[0] (p).type: unknown element type 'Slider'"),
    (('h = "1 ms"', "h = 0"), "solver.step.h: must be > 0 s"),
])
def test_bad_files_name_key_value_and_expectation(tmp_path, edit, message):
    text = BLOCK.replace(*edit)
    with pytest.raises(ModelFileError) as exc:
        load_model(_write(tmp_path, text))
    assert message in str(exc.value)


def test_impossible_inertia_is_refused_with_the_file_name(tmp_path):
    """Refused when the file is read (the schema checks the inertia a body can have), naming
    the file and the key."""
    path = _write(tmp_path, BLOCK.replace("inertia = [0.1, 0.1, 0.1]", "inertia = [0.1, 0.1, 0.5]"))
    with pytest.raises(ModelFileError, match=r"(?s)m\.toml.*bodies\[0\] \(block\)\.inertia: "
                       "principal moments .* violate the triangle inequality"):
        load_model(path)


def test_overrides_by_dotted_key_and_item_name(tmp_path):
    path = _write(tmp_path, BLOCK)
    model = load_model(path, ["solver.t_end=0.2", 'bodies.block.mass="8 kg"',
                              "elements.s.stiffness=800"])
    assert model.meta["scenario"].t_end == 0.2
    assert model.nodes[0].mass == 8.0
    with pytest.raises(ModelFileError, match="no item 'ghost' in bodies"):
        load_model(path, ["bodies.ghost.mass=1"])
    with pytest.raises(ModelFileError, match="expected KEY=VALUE"):
        load_model(path, ["solver.t_end"])


# -- the commands ----------------------------------------------------------------------------


def test_run_plot_round_trip(tmp_path):
    path = _write(tmp_path, BLOCK)
    proc = _cli("run", str(path), "--json", "--set", "solver.t_end=0.3", "--out",
                str(tmp_path / "r.nc"), "--csv", str(tmp_path / "r.csv"))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert summary["success"] and summary["steps"] == 300
    assert abs(summary["energy_balance_error"]) < 1e-6
    assert summary["final"]["block.position"][2] == pytest.approx(1 + 0.1 * np.cos(3.0),
                                                                  abs=1e-3)
    res = dd.load_results(tmp_path / "r.nc")
    assert "block" in res.dataset.attrs["model_file"]
    assert json.loads(res.dataset.attrs["overrides"]) == ["solver.t_end=0.3"]
    np.testing.assert_allclose(res.time, [0.0, 0.1, 0.2, 0.3])
    assert (tmp_path / "r.csv").read_text().startswith("time [s],")
    proc = _cli("plot", str(tmp_path / "r.nc"), "--out", str(tmp_path / "figs"))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "figs" / "bodies.png").stat().st_size > 5000
    assert (tmp_path / "figs" / "energy.png").exists()


def test_bad_file_exits_2_without_traceback(tmp_path):
    path = _write(tmp_path, BLOCK.replace('mass = "2 kg"', "mass = -1"))
    proc = _cli("run", str(path))
    assert proc.returncode == 2
    assert "bodies[0] (block).mass: must be > 0 kg (got -1)" in proc.stderr
    assert "Traceback" not in proc.stderr
    proc = _cli("run", str(tmp_path / "missing.toml"))
    assert proc.returncode == 2 and "no such file" in proc.stderr


def test_failed_run_exits_1_and_keeps_partial_results(tmp_path):
    text = BLOCK + textwrap.dedent("""
        [[elements]]
        type = "JointDriver"
        name = "kick"
        joint = "p"
        quantity = "speed"
        function = { type = "table", times = [0, 0.2, 0.2000001, 1], values = [0, 0, 50, 50] }
    """)
    # a prismatic joint has no rotation axis: bad input first
    proc = _cli("run", str(_write(tmp_path, text)))
    assert proc.returncode == 2
    assert "JointDriver 'kick': joint 'p' is a Prismatic" in proc.stderr
    text = BLOCK.replace('type = "Prismatic"', 'type = "Cylindrical"').replace(
        'step = { mode = "fixed", h = "1 ms" }',
        'step = { mode = "adaptive", h0 = "1 ms", h_min = "0.1 ms", h_max = "10 ms" }')
    text += textwrap.dedent("""
        [[elements]]
        type = "JointDriver"
        name = "kick"
        joint = "p"
        quantity = "speed"
        function = { type = "table", times = [0, 0.2, 0.2000001, 1], values = [0, 0, 50, 50] }
    """)
    path = _write(tmp_path, text, "kick.toml")
    proc = _cli("run", str(path), "--out", str(tmp_path / "kick.nc"))
    assert proc.returncode == 1, proc.stderr
    assert "simulation stopped at t = 0.2" in proc.stdout + proc.stderr
    assert not (tmp_path / "kick.nc").exists()
    part = dd.load_results(tmp_path / "kick.partial.nc")
    assert not part.success and part.time[-1] == pytest.approx(0.2, abs=1e-3)


@pytest.mark.skipif(os.name != "posix", reason="SIGINT delivery")
def test_interrupted_run_leaves_a_readable_partial_result(tmp_path):
    path = _write(tmp_path, BLOCK.replace('t_end = "0.5 s"', 't_end = "1000 s"'))
    proc = subprocess.Popen([sys.executable, "-m", "drivedyn.cli", "run", str(path), "--out",
                             str(tmp_path / "long.nc"), "--verbose"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    # --verbose logs every accepted step ("t = ... s ..."): interrupt only once the time loop
    # is well under way (not while kernels load or the initial state is computed)
    deadline = time.time() + 300
    t_run = 0.0
    while t_run < 0.5 and time.time() < deadline and proc.poll() is None:
        line = proc.stderr.readline()
        if line.startswith("t = "):
            t_run = float(line.split()[2])
    proc.send_signal(signal.SIGINT)
    _out, err = proc.communicate(timeout=120)
    assert proc.returncode == 1, err
    part = dd.load_results(tmp_path / "long.partial.nc")
    assert "interrupted by the user" in part.message
    assert 0.1 < part.time[-1] < 1000
    assert not (tmp_path / "long.nc").exists()
    assert not list(tmp_path.glob("*.part"))


def test_models_command_lists_shipped_files():
    proc = _cli("models")
    assert proc.returncode == 0
    assert "pendulum" in proc.stdout and "slider_crank" in proc.stdout


def test_generic_elements_section(tmp_path):
    """Any element type by class name, with unit strings converted to SI."""
    text = BLOCK + textwrap.dedent("""
        [[elements]]
        type = "SpringDamper"
        name = "extra"
        marker_a = "anchor"
        marker_b = "slider"
        stiffness = "0.2 kN/m"
        free_length = "100 cm"
    """)
    model = load_model(_write(tmp_path, text))
    res = dd.simulate(model, 0.3)
    # two equal springs in parallel: omega = sqrt(2 k / m) = sqrt(200) rad/s
    z = res["block.position"].values[:, 2] - 1.0
    np.testing.assert_allclose(z, 0.1 * np.cos(np.sqrt(200.0) * res.time), atol=2e-4)
    bad = text.replace('stiffness = "0.2 kN/m"', 'stiffnes = 200')
    with pytest.raises(ModelFileError, match=r"elements\[2\] \(extra\).stiffnes: unknown key "
                                             r"\(did you mean 'stiffness'\?\) \(SpringDamper "
                                             "parameters: marker_a, marker_b, stiffness"):
        load_model(_write(tmp_path, bad, "bad.toml"))
    bad = text.replace('type = "SpringDamper"\nname = "extra"', 'type = "Spring"\nname = "extra"')
    with pytest.raises(ModelFileError, match="unknown element type 'Spring'"):
        load_model(_write(tmp_path, bad, "bad2.toml"))


# the dedicated element sections of older files: every one, then the same model in
# [[elements]] (in the order the loader gives the old sections: joints, springs, torsional
# springs, forces, torques, drivers, speed-difference drivers, then the file's [[elements]])
LEGACY_HEAD = """
[model]
name = "legacy"

[[bodies]]
name = "a"
mass = 1
inertia = [1, 1, 1]

[[bodies]]
name = "b"
mass = 1
inertia = [1, 1, 1]
position = [0, 0, 1]

[[markers]]
name = "g"
body = "ground"
axis = [0, 0, 1]

[[markers]]
name = "ma"
body = "a"
axis = [0, 0, 1]

[[markers]]
name = "g2"
body = "ground"
position = [0, 0, 1]
axis = [0, 0, 1]

[[markers]]
name = "mb"
body = "b"
axis = [0, 0, 1]

[functions]
ramp = { type = "ramp", t0 = 0, t1 = 1, v0 = 0, v1 = 1 }
"""

LEGACY_SECTIONS = """
[[elements]]
type = "TorsionalSpringDamper"
name = "own"
marker_a = "g2"
marker_b = "mb"
stiffness = 5

[[speed_difference_drivers]]
name = "sd"
joint_1 = "ja"
joint_2 = "jb"
function = 0.5
p = 3e5

[[drivers]]
name = "d"
joint = "ja"
quantity = "angle"
function = { type = "ramp", t0 = 0, t1 = 1, v0 = 0, v1 = 1 }
k = 1e5

[[torques]]
name = "t"
marker = "ma"
vector = [0, 0, "2 N m"]
function = 3

[[forces]]
name = "f"
marker = "mb"
vector = [0, "1 kN", 0]
function = "ramp"
frame = "marker"

[[torsional_springs]]
name = "ts"
marker_a = "g"
marker_b = "ma"
stiffness = "10 N m/rad"
damping = 0.1
free_angle = "5 deg"
preload = "0.5 N m"

[[springs]]
name = "s"
marker_a = "g"
marker_b = "mb"
stiffness = "2 kN/m"
damping = 3
free_length = "90 cm"
preload = "1 N"

[[joints]]
type = "hinge"
name = "ja"
marker_a = "g"
marker_b = "ma"
k = 1e6
p = 2e6

[[joints]]
type = "screw"
name = "jb"
marker_a = "g2"
marker_b = "mb"
pitch = "2 mm"
"""

ELEMENTS = """
[[elements]]
type = "Hinge"
name = "ja"
marker_a = "g"
marker_b = "ma"
k = 1e6
p = 2e6

[[elements]]
type = "Screw"
name = "jb"
marker_a = "g2"
marker_b = "mb"
pitch = "2 mm"

[[elements]]
type = "SpringDamper"
name = "s"
marker_a = "g"
marker_b = "mb"
stiffness = "2 kN/m"
damping = 3
free_length = "90 cm"
preload = "1 N"

[[elements]]
type = "TorsionalSpringDamper"
name = "ts"
marker_a = "g"
marker_b = "ma"
stiffness = "10 N m/rad"
damping = 0.1
free_angle = "5 deg"
preload = "0.5 N m"

[[elements]]
type = "Force"
name = "f"
marker = "mb"
vector = [0, "1 kN", 0]
function = "ramp"
frame = "marker"

[[elements]]
type = "Torque"
name = "t"
marker = "ma"
vector = [0, 0, "2 N m"]
function = 3

[[elements]]
type = "JointDriver"
name = "d"
joint = "ja"
quantity = "angle"
function = { type = "ramp", t0 = 0, t1 = 1, v0 = 0, v1 = 1 }
k = 1e5

[[elements]]
type = "SpeedDifferenceDriver"
name = "sd"
joint_1 = "ja"
joint_2 = "jb"
function = 0.5
p = 3e5

[[elements]]
type = "TorsionalSpringDamper"
name = "own"
marker_a = "g2"
marker_b = "mb"
stiffness = 5
"""


def _spec_of(path):
    from drivedyn.config.loader import build_spec, read_model_file

    mf, _, _ = read_model_file(path)
    return build_spec(mf)


def test_deprecated_sections_load_as_elements(tmp_path):
    """The dedicated sections still load: the same Spec, element by element and in the same
    order, as the file written with [[elements]], and one DeprecationWarning per section
    naming the section, the file and the replacement."""
    import warnings

    new = _write(tmp_path, LEGACY_HEAD + ELEMENTS, "new.toml")
    old = _write(tmp_path, LEGACY_HEAD + LEGACY_SECTIONS, "old.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the [[elements]] file warns of nothing
        expected = _spec_of(new)
    with pytest.warns(DeprecationWarning) as caught:
        got = _spec_of(old)
    assert [(type(e), e) for e in got.elements] == [(type(e), e) for e in expected.elements]
    assert [e.name for e in got.elements] == ["ja", "jb", "s", "ts", "f", "t", "d", "sd", "own"]
    assert got.element("f").vector == [0.0, 1000.0, 0.0]
    assert got.element("ts").free_angle == pytest.approx(np.radians(5.0), rel=1e-15)
    messages = [str(w.message) for w in caught if w.category is DeprecationWarning]
    assert len(messages) == 7
    assert messages[0] == (f"model file {old}: [[joints]] is deprecated; write [[elements]] "
                           'with type = "Hinge" or "Screw" (the element\'s class name)')
    for section, cls in [("springs", "SpringDamper"), ("torsional_springs",
                                                       "TorsionalSpringDamper"),
                         ("forces", "Force"), ("torques", "Torque"),
                         ("drivers", "JointDriver"),
                         ("speed_difference_drivers", "SpeedDifferenceDriver")]:
        assert (f'[[{section}]] is deprecated; write [[elements]] with type = "{cls}"'
                in "\n".join(messages))
    # the compiled models are the same too (groups in the same order)
    with pytest.warns(DeprecationWarning):
        m_old = load_model(old)
    m_new = load_model(new)
    assert [g.family for g in m_old.groups] == [g.family for g in m_new.groups]
    assert len(m_old.meta["notes"]) == 7 and m_new.meta["notes"] == []


def test_deprecated_section_noted_by_the_cli(tmp_path):
    """`drivedyn run` prints each deprecation as a one-line note and runs the model."""
    legacy = BLOCK.replace('[[elements]]\ntype = "Prismatic"',
                           '[[joints]]\ntype = "prismatic"').replace(
        '[[elements]]\ntype = "SpringDamper"', "[[springs]]")
    assert "[[elements]]" not in legacy
    path = _write(tmp_path, legacy, "legacy.toml")
    proc = _cli("run", str(path), "--t-end", "0.01", "--out", str(tmp_path / "r.nc"))
    assert proc.returncode == 0, proc.stderr
    notes = [ln for ln in proc.stderr.splitlines() if ln.startswith("note:")]
    assert notes == [
        f"note: model file {path}: [[joints]] is deprecated; write [[elements]] with type = "
        "\"Prismatic\" (the element's class name)",
        f"note: model file {path}: [[springs]] is deprecated; write [[elements]] with type = "
        "\"SpringDamper\" (the element's class name)"]


@pytest.mark.parametrize(("edit", "message"), [
    (('stiffness = "2 kN/m"', 'stifness = "2 kN/m"'),
     "springs[0] (s).stifness: unknown key (did you mean 'stiffness'?)"),
    (('stiffness = "2 kN/m"', 'stiffness = "2 kg"'),
     "springs[0] (s).stiffness: '2 kg' is in kg, expected N/m"),
    (('type = "hinge"', 'type = "hinje"'),
     "joints[0] (ja).type: unknown joint type 'hinje' (did you mean 'hinge'?)"),
    (('type = "hinge"', 'type = "Hinge"'), "joints[0] (ja).type: unknown joint type 'Hinge'"),
    (('pitch = "2 mm"\n', ""), "joints[1] (jb).pitch: required key is missing"),
    (("k = 1e6\n", 'k = 1e6\npitch = "1 mm"\n'),
     "joints[0] (ja).pitch: only a screw joint takes a pitch"),
    (('[[torques]]\nname = "t"', '[[torques]]\ntype = "Torque"\nname = "t"'),
     "torques[0] (t).type: unknown key"),
    (('function = "ramp"', 'function = "rampe"'),
     "forces[0] (f).function: unknown function 'rampe' (did you mean 'ramp'?)"),
    (('quantity = "angle"', 'quantity = "position"'),
     "drivers[0] (d).quantity: expected 'angle' or 'speed', got 'position'"),
    (('[[springs]]\nname = "s"\n', "[[springs]]\n"), "springs[0].name: required key is missing"),
])
def test_deprecated_sections_errors_name_their_entry(tmp_path, edit, message):
    text = (LEGACY_HEAD + LEGACY_SECTIONS).replace(*edit)
    assert text != LEGACY_HEAD + LEGACY_SECTIONS
    with pytest.raises(ModelFileError) as exc:
        load_model(_write(tmp_path, text))
    assert message in str(exc.value)


def test_shipped_bouncing_ball_file_bounces_with_the_laws_restitution():
    """The model-file version of the seeds' benchmark: the first rebound apex is e^2 h0 with
    e the restitution the exact relation predicts for the Lankarani-Nikravesh law (gravity
    during the ~0.1 ms contact shifts it by ~1e-4 relative, see tests/elements/test_contact.py)."""
    from drivedyn.elements.contact.impact_laws import NormalLaw

    model = load_model("bouncing_ball", ["solver.t_end=0.9"])
    res = dd.simulate(model)
    assert res.success, res.message
    z = res["ball.position"].values[:, 2]
    t = res.time
    first = (t > 0.5) & (t < 0.9)  # first impact at t = sqrt(0.2) = 0.447 s
    e = NormalLaw(1e10, 1.5, "lankarani-nikravesh", 0.8).achieved_restitution
    assert z[first].max() == pytest.approx(e**2, rel=2e-3)  # 2 ms output sampling of the apex


@pytest.mark.skipif(os.name != "posix", reason="SIGINT delivery")
def test_ctrl_c_in_the_time_loop_is_raised_at_the_next_progress_call():
    """The CLI's progress callback holds a Ctrl-C that comes during the time loop and raises
    it at its next call (in drivedyn's code, never inside a library's); before its first
    call Ctrl-C raises at once; the previous handler is back afterwards. Fails with the
    signal raised where it lands (the handler raising at once after the first call)."""
    from drivedyn.cli.progress import progress_bar

    before = signal.getsignal(signal.SIGINT)
    with progress_bar(1.0, enabled=False) as cb:
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)  # the handler runs at the next bytecode; never sleeps this long
        cb(0.1, 1e-3, 1)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)  # held: nothing raised here
        with pytest.raises(KeyboardInterrupt):
            cb(0.2, 1e-3, 2)
        cb(0.3, 1e-3, 3)  # raised once
    assert signal.getsignal(signal.SIGINT) is before
