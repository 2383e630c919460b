"""A catalogue of malformed inputs: each must end with exit code 2, one message naming the
file or the key (dotted path) and what was expected, and no traceback; nothing is written.

Every entry is a small edit of a valid model (the shipped pendulum, plus a gear pair and a
contact in ``[[elements]]``, after its hinge: ``elements[1]``), or a bad option of a
command. The checks run the command line
in-process (``CliRunner``) so that a Python exception escaping any layer shows up as a
non-2 exit code or a traceback in the output.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from drivedyn.cli import main

BASE = """\
[model]
name = "pendulum"
gravity = [0, 0, -9.81]

[[bodies]]
name = "rod"
mass = "1 kg"
inertia = [1e-6, 0.0833, 0.0833]
com = ["0.5 m", 0, 0]
rotation = { axis = [0, 1, 0], angle = "-0.4292 rad" }

[[markers]]
name = "pivot"
body = "ground"
axis = [0, 1, 0]

[[markers]]
name = "rod_end"
body = "rod"
axis = [0, 1, 0]

[[elements]]
type = "Hinge"
name = "hinge"
marker_a = "pivot"
marker_b = "rod_end"

[solver]
t_end = "0.05 s"
rho_inf = 0.9
step = { mode = "fixed", h = "1 ms" }

[output]
dt = "10 ms"
"""

GEARS = """
[[bodies]]
name = "pinion"
mass = 1.0
inertia = [1e-3, 1e-3, 1e-3]

[[bodies]]
name = "wheel"
mass = 2.0
inertia = [4e-3, 4e-3, 4e-3]
position = ["90 mm", 0, 0]

[[markers]]
name = "mp"
body = "pinion"

[[markers]]
name = "mw"
body = "wheel"

[[elements]]
type = "GearPair"
name = "mesh"
marker_a = "mp"
marker_b = "mw"
teeth_a = 20
teeth_b = 40
module = "3 mm"
face_width = "20 mm"
"""

CONTACT = """
[[markers]]
name = "floor"
body = "ground"

[[elements]]
type = "PlaneContact"
name = "impact"
marker_a = "floor"
marker_b = "rod_end"
law = { stiffness = 1e10, exponent = 1.5, law = "lankarani-nikravesh", restitution = 0.8 }
"""

ADAPTIVE = 'step = { mode = "adaptive", h0 = "0.1 ms", h_min = "1e-9 s", h_max = "1 ms" }'


def edit(old: str, new: str, base: str = BASE) -> str:
    assert old in base, old
    return base.replace(old, new, 1)


# (id, file text or bytes (None: no file), extra command-line arguments, words the message
# must contain (case-insensitive); "{file}" stands for the model file's path)
FILE_CASES: list[tuple[str, str | bytes | None, list[str], list[str]]] = [
    # files that are not model files
    ("empty file", "", [], ["{file}", "nothing to simulate"]),
    ("not TOML", "this is = not = toml\n", [], ["{file}", "TOML"]),
    ("non-UTF-8 bytes", b"[model]\nname = \"\xff\xfe\"\n", [], ["{file}", "UTF-8"]),
    ("only comments", "# a model\n", [], ["{file}", "nothing to simulate"]),
    ("no bodies", "[model]\nname = \"x\"\n[solver]\nt_end = 1\n", [],
     ["{file}", "nothing to simulate"]),
    # types and keys
    ("mass not a number", edit('mass = "1 kg"', 'mass = "heavy"'), [], ["bodies[0]", "mass"]),
    ("rho_inf a string", edit("rho_inf = 0.9", 'rho_inf = "high"'), [], ["solver.rho_inf"]),
    ("max_iter a string", edit("rho_inf = 0.9", 'rho_inf = 0.9\nnewton = { max_iter = "ten" }'),
     [], ["solver.newton.max_iter"]),
    ("max_iter a float", edit("rho_inf = 0.9", "rho_inf = 0.9\nnewton = { max_iter = 2.5 }"),
     [], ["solver.newton.max_iter"]),
    ("mass missing", edit('mass = "1 kg"\n', ""), [], ["bodies[0]", "mass", "missing"]),
    ("marker body missing", edit('name = "pivot"\nbody = "ground"\n', 'name = "pivot"\n'), [],
     ["markers[0]", "body", "missing"]),
    ("misspelt section", edit("[solver]", "[solvr]"), [], ["solvr", "did you mean", "solver"]),
    ("misspelt body key", edit('mass = "1 kg"', 'mass = "1 kg"\nmas = 2'), [],
     ["bodies[0]", "mas", "did you mean", "mass"]),
    ("misspelt joint key", edit('marker_b = "rod_end"', 'marker_b = "rod_end"\nmarkr_a = "x"'),
     [], ["elements[0] (hinge).markr_a", "did you mean", "marker_a"]),
    ("unknown joint type", edit('type = "Hinge"', 'type = "Hingee"'), [],
     ["elements[0] (hinge).type", "Hingee", "did you mean 'Hinge'"]),
    ("joint parameter in a wrong unit",
     edit('marker_b = "rod_end"', 'marker_b = "rod_end"\nk = "1 N"'),
     [], ["elements[0] (hinge).k", "'1 N' is in N, expected N/m or N m/rad"]),
    ("dimensionless parameter with a unit",
     BASE + CONTACT.replace("restitution = 0.8", 'restitution = "0.8 m"'),
     [], ["elements[1] (impact).law.restitution", "plain number", "0.8 m"]),
    ("unknown element type", BASE + CONTACT.replace("PlaneContact", "PlainContact"), [],
     ["elements[1] (impact).type", "PlainContact", "did you mean", "PlaneContact"]),
    ("unknown element parameter", BASE + CONTACT.replace('name = "impact"',
                                                         'name = "impact"\nstifness = 3'), [],
     ["elements[1] (impact).stifness", "unknown key"]),
    ("unknown time-function type",
     BASE + '[[elements]]\ntype = "Torque"\nname = "t"\nmarker = "rod_end"\n'
            'vector = [0, 0, 1]\nfunction = { type = "sawtooth" }\n', [],
     ["elements[1] (t).function", "sawtooth"]),
    ("undefined time function",
     BASE + '[[elements]]\ntype = "Torque"\nname = "t"\nmarker = "rod_end"\n'
            'vector = [0, 0, 1]\nfunction = "ramp_up"\n', [],
     ["elements[1] (t).function", "ramp_up"]),
    ("torque vector of two values",
     BASE + '[[elements]]\ntype = "Torque"\nname = "t"\nmarker = "rod_end"\n'
            'vector = [0, 1]\n', [], ["elements[1] (t).vector", "3 finite numbers"]),
    ("unknown load frame",
     BASE + '[[elements]]\ntype = "Force"\nname = "f"\nmarker = "rod_end"\n'
            'vector = [0, 0, "1 N"]\nframe = "body"\n', [],
     ["elements[1] (f).frame", "'global' or 'marker'", "body"]),
    ("driver quantity", BASE + '[[elements]]\ntype = "JointDriver"\nname = "d"\n'
                               'joint = "hinge"\nquantity = "torque"\n', [],
     ["elements[1] (d).quantity", "'angle' or 'speed'", "torque"]),
    ("element without a required key", BASE + '[[elements]]\ntype = "JointDriver"\n'
                                               'name = "d"\n', [],
     ["elements[1] (d).joint", "missing"]),
    ("deprecated section, misspelt key", BASE + '[[springs]]\nname = "s"\n'
                                                'marker_a = "pivot"\nmarker_b = "rod_end"\n'
                                                'stifness = 5\n', [],
     ["springs[0] (s).stifness", "did you mean", "stiffness"]),
    # non-physical values
    ("negative mass", edit('mass = "1 kg"', 'mass = "-1 kg"'), [], ["bodies[0]", "mass", "> 0"]),
    ("zero mass", edit('mass = "1 kg"', "mass = 0"), [], ["bodies[0]", "mass", "> 0"]),
    ("NaN mass", edit('mass = "1 kg"', "mass = nan"), [], ["bodies[0]", "mass", "finite"]),
    ("infinite gravity", edit("gravity = [0, 0, -9.81]", "gravity = [0, 0, -inf]"), [],
     ["model.gravity", "finite"]),
    ("negative inertia", edit("inertia = [1e-6, 0.0833, 0.0833]", "inertia = [1e-6, -1, 1]"),
     [], ["rod", "inertia", "positive"]),
    ("inertia breaks the triangle inequality",
     edit("inertia = [1e-6, 0.0833, 0.0833]", "inertia = [1, 1, 5]"), [],
     ["rod", "inertia", "triangle"]),
    ("absurd mass", edit('mass = "1 kg"', 'mass = "1e12 kg"'), [], ["bodies[0]", "mass", "kg"]),
    ("absurd length", edit('com = ["0.5 m", 0, 0]', 'com = ["5e6 m", 0, 0]'), [],
     ["bodies[0]", "com"]),
    ("wrong unit dimension", edit('mass = "1 kg"', 'mass = "1 m"'), [],
     ["bodies[0]", "mass", "mass"]),
    ("unknown unit", edit('mass = "1 kg"', 'mass = "1 kgg"'), [], ["bodies[0]", "mass", "kgg"]),
    ("negative spring stiffness",
     BASE + '[[elements]]\ntype = "SpringDamper"\nname = "s"\nmarker_a = "pivot"\n'
            'marker_b = "rod_end"\nstiffness = -5\n', [],
     ["elements[1] (s).stiffness", ">= 0", "-5"]),
    ("spring stiffness in kg",
     BASE + '[[elements]]\ntype = "SpringDamper"\nname = "s"\nmarker_a = "pivot"\n'
            'marker_b = "rod_end"\nstiffness = "5 kg"\n', [],
     ["elements[1] (s).stiffness", "'5 kg' is in kg, expected N/m"]),
    ("restitution above 1", BASE + CONTACT.replace("restitution = 0.8", "restitution = 1.5"),
     [], ["impact", "restitution"]),
    ("negative friction", BASE + CONTACT.replace("restitution = 0.8 }",
                                                 "restitution = 0.8 }\nfriction = { mu = -0.1 }"),
     [], ["impact", "mu"]),
    ("element stiffness in kg", BASE + GEARS.replace('face_width = "20 mm"',
                                                     'face_width = "20 mm"\nstiffness = "1e8 kg"'),
     [], ["elements[1] (mesh).stiffness", "kg"]),
    ("element length in seconds", BASE + GEARS.replace('module = "3 mm"', 'module = "3 s"'),
     [], ["elements[1] (mesh).module"]),
    ("element NaN parameter", BASE + GEARS.replace("teeth_a = 20", "teeth_a = nan"), [],
     ["mesh", "teeth_a"]),
    ("element string for integer", BASE + GEARS.replace("teeth_a = 20", 'teeth_a = "many"'), [],
     ["mesh", "teeth_a"]),
    # references and names
    ("marker on a missing body", edit('body = "rod"', 'body = "rdo"'), [],
     ["rod_end", "rdo", "did you mean", "rod"]),
    ("joint on a missing marker", edit('marker_b = "rod_end"', 'marker_b = "rod_ned"'), [],
     ["hinge", "rod_ned", "did you mean", "rod_end"]),
    ("duplicate body", BASE.replace("[[markers]]", '[[bodies]]\nname = "rod"\nmass = 1\n'
                                    "inertia = [1, 1, 1]\n\n[[markers]]", 1), [],
     ["rod", "duplicate"]),
    ("duplicate element", BASE + '[[elements]]\ntype = "Hinge"\nname = "hinge"\n'
                                 'marker_a = "pivot"\nmarker_b = "rod_end"\n', [],
     ["hinge", "duplicate"]),
    ("zero rotation axis", edit("axis = [0, 1, 0], angle", "axis = [0, 0, 0], angle"), [],
     ["bodies[0]", "rod", "rotation", "axis"]),
    # gear geometry
    ("gear centre distance off", BASE + GEARS.replace('"90 mm"', '"95 mm"'), [],
     ["mesh", "centre distance"]),
    ("gear undercut", BASE + GEARS.replace("teeth_a = 20", "teeth_a = 8").replace(
        '"90 mm"', '"72 mm"'), [], ["mesh", "undercut", "teeth_a"]),
    # time settings
    ("end time zero", edit('t_end = "0.05 s"', "t_end = 0"), [], ["solver.t_end", "> 0"]),
    ("step zero", edit('h = "1 ms"', "h = 0"), [], ["solver.step.h", "> 0"]),
    ("step longer than the run", edit('h = "1 ms"', 'h = "1 s"'), [],
     ["solver", "step.h", "t_end"]),
    ("h_min above h_max", edit('step = { mode = "fixed", h = "1 ms" }',
                               ADAPTIVE.replace('"1e-9 s"', '"1e-2 s"')), [],
     ["h_min", "h_max"]),
    ("infinite Newton tolerance", edit("rho_inf = 0.9", "rho_inf = 0.9\nnewton = { tol = inf }"),
     [], ["solver.newton.tol", "finite"]),
    ("NaN rtol", edit('step = { mode = "fixed", h = "1 ms" }',
                      ADAPTIVE.replace("}", ", rtol = nan }")), [], ["solver.step.rtol"]),
    ("rho_inf above 1", edit("rho_inf = 0.9", "rho_inf = 1.5"), [], ["solver.rho_inf"]),
    ("negative output step", edit('dt = "10 ms"', "dt = -1"), [], ["output.dt"]),
    ("output time NaN", edit('dt = "10 ms"', "times = [0, nan]"), [], ["output.times"]),
    # --set
    ("--set unknown key", BASE, ["--set", "solver.t_endd=2"],
     ["solver.t_endd", "did you mean", "t_end"]),
    ("--set bad value", BASE, ["--set", "solver.t_end=abc"], ["solver.t_end"]),
    ("--set without =", BASE, ["--set", "solver.t_end"], ["--set", "KEY=VALUE"]),
    ("--set missing item", BASE, ["--set", "bodies.rdo.mass=2"], ["rdo", "rod"]),
    # options of run
    ("--t-end NaN", BASE, ["--t-end", "nan"], ["--t-end", "finite"]),
    ("--t-end negative", BASE, ["--t-end", "-1"], ["--t-end"]),
]


def _message_ok(out: str, words: list[str], file: Path | None) -> list[str]:
    low = out.lower()
    missing = []
    for w in words:
        w = w.replace("{file}", str(file)) if file is not None else w
        if w.lower() not in low:
            missing.append(w)
    return missing


def _check(res, words: list[str], file: Path | None = None) -> None:
    out = res.output + (res.stderr if res.stderr_bytes is not None else "")
    assert res.exit_code == 2, f"exit {res.exit_code}: {out}\n{res.exception!r}"
    assert "Traceback" not in out, out
    missing = _message_ok(out, words, file)
    assert not missing, f"message lacks {missing}: {out}"


@pytest.mark.parametrize("text, args, words",
                         [pytest.param(t, a, w, id=i) for i, t, a, w in FILE_CASES])
def test_malformed_model_file(tmp_path: Path, text, args, words) -> None:
    path = tmp_path / "model.toml"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    out = tmp_path / "r.nc"
    res = CliRunner().invoke(main, ["run", str(path), "--out", str(out), *args])
    _check(res, words, path)
    assert not out.exists() and not list(tmp_path.glob("*.nc"))


def test_missing_file(tmp_path: Path) -> None:
    res = CliRunner().invoke(main, ["run", str(tmp_path / "nope.toml")])
    _check(res, ["nope.toml", "no such file"])


def test_directory_as_model(tmp_path: Path) -> None:
    res = CliRunner().invoke(main, ["run", str(tmp_path)])
    _check(res, [str(tmp_path), "folder"])


@pytest.mark.parametrize("where", ["parent is a file", "a folder", "csv parent is a file"])
def test_unwritable_output_refused_before_the_run(tmp_path: Path, where: str) -> None:
    model = tmp_path / "m.toml"
    model.write_text(BASE)
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    args = {"parent is a file": ["--out", str(blocker / "r.nc")],
            "a folder": ["--out", str(tmp_path)],
            "csv parent is a file": ["--out", str(tmp_path / "r.nc"),
                                     "--csv", str(blocker / "r.csv")]}[where]
    res = CliRunner().invoke(main, ["run", str(model), *args])
    _check(res, ["--", str(blocker if "file" in where else tmp_path)])
    assert "simulating" not in res.output


@pytest.mark.parametrize("content, words", [
    ("not a results file", ["{file}", "results file"]),
    (None, ["{file}"]),
])
def test_plot_bad_results_file(tmp_path: Path, content, words) -> None:
    path = tmp_path / "r.nc"
    if content is not None:
        path.write_text(content)
    res = CliRunner().invoke(main, ["plot", str(path), "--out", str(tmp_path / "f")])
    _check(res, words, path)


def test_plot_netcdf_not_from_drivedyn(tmp_path: Path) -> None:
    import numpy as np
    import xarray as xr

    path = tmp_path / "other.nc"
    xr.Dataset({"a": ("x", np.arange(3.0))}).to_netcdf(path)
    res = CliRunner().invoke(main, ["plot", str(path), "--out", str(tmp_path / "f")])
    _check(res, [str(path), "drivedyn results"], path)


TDR_CASES = [
    (["--mode", "7"], ["--mode"]),
    (["--torque", "-5"], ["--torque"]),
    (["--torque", "nan"], ["--torque", "finite"]),
    (["--torque", "inf"], ["--torque", "finite"]),
    (["--speed-diff", "0"], ["--speed-diff"]),
    (["--friction-scale", "nan"], ["--friction-scale"]),
    (["--set", "pockets.muu=0.1"], ["pockets.muu"]),
]


@pytest.mark.parametrize("args, words", TDR_CASES, ids=[" ".join(a) for a, _ in TDR_CASES])
def test_tdr_bad_options(args: list[str], words: list[str]) -> None:
    res = CliRunner().invoke(main, ["tdr", "torsen-c", "--analytic-only", *args])
    _check(res, words)


CALIBRATE_CASES = [
    (["--bounds", "0.5", "0.1"], ["--bounds"]),
    (["--bounds", "nan", "0.1"], ["--bounds"]),
    (["--target", "one=4"], ["--target"]),
    (["--target", "1=nan"], ["--target"]),
    (["--free", "washers.nope.mu"], ["washers.nope.mu"]),
]


@pytest.mark.parametrize("args, words", CALIBRATE_CASES,
                         ids=[" ".join(a) for a, _ in CALIBRATE_CASES])
def test_calibrate_bad_options(args: list[str], words: list[str], tmp_path: Path) -> None:
    res = CliRunner().invoke(main, ["calibrate", "torsen-c", "--no-confirm", *args,
                                    "--out", str(tmp_path / "c.toml")])
    _check(res, words)
    assert not (tmp_path / "c.toml").exists()


BOUNCE_CASES = [(["--e", "1.5"], ["--e"]), (["--k", "nan"], ["--k"]),
                (["--t-end", "inf"], ["--t-end"]), (["--mass", "-1"], ["--mass"])]


@pytest.mark.parametrize("args, words", BOUNCE_CASES, ids=[" ".join(a) for a, _ in BOUNCE_CASES])
def test_bounce_bad_options(args: list[str], words: list[str]) -> None:
    _check(CliRunner().invoke(main, ["bounce", *args]), words)


def test_other_commands_bad_options(tmp_path: Path) -> None:
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    runner = CliRunner()
    _check(runner.invoke(main, ["validate", "--case", "pendulm"]), ["pendulm", "pendulum"])
    _check(runner.invoke(main, ["validate", "--report", str(a_file)]), ["--report", "is a file"])
    _check(runner.invoke(main, ["models", "--show", "pendulm"]), ["pendulm", "pendulum"])
    _check(runner.invoke(main, ["bounce", "--plot", str(a_file / "b.png")]), ["--plot"])
    _check(runner.invoke(main, ["calibrate", "torsen-c", "--out", str(a_file / "c.toml")]),
           ["--out"])
    model = tmp_path / "m.toml"
    model.write_text(BASE)
    res = runner.invoke(main, ["run", str(model), "--out", str(tmp_path / "r.nc")])
    assert res.exit_code == 0, res.output
    _check(runner.invoke(main, ["plot", str(tmp_path / "r.nc"), "--vars", "zzz*", "--out",
                                str(tmp_path / "f")]), ["zzz*"])
    _check(runner.invoke(main, ["plot", str(tmp_path / "r.nc"), "--out", str(a_file)]),
           ["--out", "is a file"])
