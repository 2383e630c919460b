"""Fuzzing the differential and vehicle model files through ``--set`` (hypothesis).

Every leaf key of the shipped ``torsen-c``, ``torsen-b`` and ``vehicle-4wd`` files, enumerated
from their schemas (keys the file leaves at their defaults included), set to an edge value:
zero, negative, huge, NaN, infinite, a string with a unit (of another dimension for most
keys), a word, a wrong type (true, a list, a table), or for lists a list of such values. The
commands users run on them, with short end times:

* ``drivedyn tdr FILE --analytic-only`` (schema, geometry checks, analytic model) and
  ``drivedyn run FILE --t-end 2 ms`` (build, compile, simulate) for the differentials;
* ``drivedyn vehicle --t-end 2 ms`` on a 2 ms window (every check included), optionally
  with the open or clutch differentials (whose bevel keys the TORSEN files leave unused).

Each outcome is clean: exit 0; exit 1 with the reason of the failure; or exit 2 with
``error: ...`` naming the file and the key set (its dotted path, or its section and its
name). Never a traceback, never an internal error.

The default profile (CI) is short and derandomized; ``pytest -m fuzz_long`` runs the long one
and the exhaustive sweep of every key and edge value.
"""

from __future__ import annotations

import re
import typing
from pathlib import Path
from typing import Any

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from pydantic import BaseModel

from drivedyn.config.loader import _library_schemas
from fuzz_common import Outcome, assert_clean, cli, long, short

#: shipped model name -> library key
MODELS = {"torsen-c": "torsen_c", "torsen-b": "torsen_b", "vehicle-4wd": "vehicle_4wd"}

#: edge values (TOML text); lists get lists of them
EDGES = ["0", "-1", "-1e-9", "1e30", "-1e30", "nan", "inf", "-inf", '"3 kg"', '"3 m"',
         '"-2 s"', "1", "1e-300", "1e9", '"abc"', '""', "true", "false", "[1, 2]",
         "{ a = 1 }"]


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out: list[type[BaseModel]] = []
    for a in typing.get_args(annotation):
        out += _models_in(a)
    return out


def leaf_keys(schema: type[BaseModel], prefix: str = "") -> list[tuple[str, Any]]:
    """(dotted key, annotation) of every value of a model file's schema: sections are
    followed, lists and tables of values are leaves."""
    out: list[tuple[str, Any]] = []
    for name, f in schema.model_fields.items():
        models = _models_in(f.annotation)
        if models and typing.get_origin(f.annotation) not in (list, dict, tuple):
            out += leaf_keys(models[0], f"{prefix}{name}.")
        else:
            out.append((f"{prefix}{name}", f.annotation))
    return out


KEYS = {name: leaf_keys(_library_schemas()[lib]) for name, lib in MODELS.items()}


def _is_sequence(annotation: Any) -> bool:
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _is_sequence(typing.get_args(annotation)[0])
    return origin in (list, tuple) or annotation is list


@st.composite
def edge_value(draw: Any, annotation: Any) -> str:
    """An edge value for a key of type ``annotation``; a list of them for list keys."""
    if _is_sequence(annotation) and draw(st.booleans()):
        n = draw(st.integers(1, 3))
        return "[" + ", ".join(draw(st.sampled_from(EDGES[:16])) for _ in range(n)) + "]"
    return draw(st.sampled_from(EDGES))


@st.composite
def overrides(draw: Any, model: str) -> tuple[str, str]:
    """(key, value) of one ``--set`` on ``model``."""
    key, annotation = draw(st.sampled_from(KEYS[model]))
    return key, draw(edge_value(annotation))


def accepted(model: str, key: str, value: str) -> bool:
    """Does ``--set key=value`` pass the schema and the checks of the parameters (then the
    commands build and simulate it)? In-process, without building the model."""
    from drivedyn.config import read_library_file
    from drivedyn.config.loader import read_vehicle_differentials
    from drivedyn.library import differentials, vehicles

    try:
        p, _, src = read_library_file(model, [f"{key}={value}"])
        if model == "vehicle-4wd":
            read_vehicle_differentials(p, src, Path("."))
            vehicles.get(p.model.library).check_parameters(p)
            vehicles.get(p.model.library).load_tyre(p)
        else:
            differentials.of(p).check(p)
    except ValueError:  # ModelFileError, ModelError, UnitError
        return False
    return True


def _takes_numbers(annotation: Any) -> bool:
    if annotation in (int, float):
        return True
    return any(_takes_numbers(a) for a in typing.get_args(annotation))


#: the keys of numbers (the records, names and switches aside): what the runs exercise
NUMERIC_KEYS = {m: [(k, a) for k, a in keys if _takes_numbers(a)
                    and not k.startswith(("calibration.", "experiment."))]
                for m, keys in KEYS.items()}


@st.composite
def accepted_overrides(draw: Any, model: str) -> tuple[str, str]:
    """An override of a number that the checks accept (edge values that are valid: zero
    friction, zero damping, a negative speed...)."""
    key, annotation = draw(st.sampled_from(NUMERIC_KEYS[model]))
    value = draw(edge_value(annotation))
    assume(accepted(model, key, value))
    return key, value


# -- the commands and their oracle ----------------------------------------------------------

def _names_key(text: str, key: str) -> bool:
    """Does a message name ``key``: its dotted path, or its section and its name (a check
    of a section, ``bench: ... t_end ...``; an item of a list, ``road.patches[0].mu``)?"""
    if key in text:
        return True
    parent, _, leaf = key.rpartition(".")
    return bool(re.search(rf"\b{re.escape(leaf)}\b", text)) and parent in text


def check_outcome(out: Outcome, source: str, key: str) -> None:
    """Clean exit; a refusal names the model file and the key."""
    assert_clean(out)
    if out.exit_code == 2:
        msg = out.text[out.text.index("error: "):]
        assert source in msg, f"the message does not name the file {source}:\n{out.show()}"
        assert _names_key(msg, key), f"the message does not name {key}:\n{out.show()}"


VEHICLE = ["vehicle", "--t-end", "0.002", "--set", "run.window=[0, 0.002]"]


def run_differential(tmp_path: Path, model: str, key: str, value: str, simulate: bool,
                     bench: bool = False) -> None:
    """``tdr --analytic-only`` and, if the file is accepted and ``simulate``, ``run`` (of
    the file's vehicle scenario, or with ``bench`` of its bench scenario)."""
    st_ = f"{key}={value}"
    out = cli(["tdr", model, "--analytic-only", "--set", st_])
    check_outcome(out, model, key)
    if out.exit_code == 2 or not simulate:
        return
    scenario = ["--set", "scenario.kind=bench"] if bench else []
    out = cli(["run", model, "--t-end", "0.002", "--out", str(tmp_path / "r.nc"), *scenario,
               "--set", st_])
    check_outcome(out, model, key)


def run_vehicle(key: str, value: str, config: str | None = None) -> None:
    """``drivedyn vehicle`` for 2 ms with ``key = value`` (and ``--compare config``)."""
    args = [*VEHICLE, "--set", f"{key}={value}"]
    if config:
        args += ["--compare", config]
    check_outcome(cli(args), "vehicle-4wd", key)


# -- the tests ------------------------------------------------------------------------------

@short(40)
@given(model=st.sampled_from(["torsen-c", "torsen-b"]), data=st.data())
def test_differential_files_refuse_or_evaluate(model: str, data: st.DataObject) -> None:
    """``drivedyn tdr --analytic-only`` on a differential file with one key at an edge value.
    Fails if an edge value crashes the schema, the geometry checks or the analytic model
    (e.g. a pressure angle below 0 reaching the involute before its range check, pockets.mu = 1
    making the analytic equilibrium fail as an internal error) or is refused without naming
    the file and the key (e.g. a check's message losing its source prefix)."""
    key, value = data.draw(overrides(model))
    run_differential(Path("."), model, key, value, simulate=False)


@short(4)
@given(model=st.sampled_from(["torsen-c", "torsen-b"]), data=st.data())
def test_differential_files_run_or_fail_cleanly(tmp_path: Path, model: str,
                                                data: st.DataObject) -> None:
    """Accepted edge values through ``drivedyn run FILE --t-end 2 ms`` too. Fails if one that
    passes the checks crashes the build, the compilation or the first steps (e.g. an infinite
    damping ratio reaching the gear mesh)."""
    key, value = data.draw(accepted_overrides(model))
    run_differential(tmp_path, model, key, value, simulate=True)


@short(10)
@given(data=st.data())
def test_vehicle_file_refuses_or_runs(data: st.DataObject) -> None:
    """``drivedyn vehicle`` for 2 ms with one key of the vehicle file at an edge value (bevel
    differential keys with the open or clutch differentials). Fails if a value crashes the
    checks or is refused without naming vehicle-4wd and the key (e.g. an infinite road
    friction reaching the tyre element, which names its element instead)."""
    key, value = data.draw(overrides("vehicle-4wd"))
    config = data.draw(st.sampled_from(["open", "clutch"])) \
        if key.startswith("differentials.bevel") else None
    run_vehicle(key, value, config)


@short(3)
@given(data=st.data())
def test_vehicle_file_runs_or_fails_cleanly(data: st.DataObject) -> None:
    """Accepted edge values through ``drivedyn vehicle`` for 2 ms. Fails if one crashes the
    build, the run or the window analysis (e.g. road friction 0 dividing by zero in the tyre
    formula, a zero engine torque in the torque balances)."""
    key, value = data.draw(accepted_overrides("vehicle-4wd"))
    config = data.draw(st.sampled_from([None, "open", "clutch", "locked"]))
    run_vehicle(key, value, config)


def test_every_key_is_enumerated() -> None:
    """The schema walk finds every section of the files (fails if the enumeration stops
    following nested sections: the fuzzing would then skip their keys)."""
    for model, keys in KEYS.items():
        names = {k for k, _ in keys}
        assert len(names) == len(keys) > 80, model
    assert "differentials.bevel.clutch.cross.mass" in {k for k, _ in KEYS["vehicle-4wd"]}
    assert "contact.elastic_washers.rated_load" in {k for k, _ in KEYS["torsen-b"]}
    assert "solver.step.atol_rot" in {k for k, _ in KEYS["torsen-c"]}


#: found by the fuzzing: each once, with what the message must name
REGRESSIONS: list[tuple[list[str], str, str]] = [
    (["tdr", "torsen-b", "--analytic-only", "--set", "gears.pressure_angle=-1"],
     "torsen-b", "gears.pressure_angle"),
    (["tdr", "torsen-c", "--analytic-only", "--set", "model.library=[1, 2]"],
     "torsen-c", "model.library"),
    (["tdr", "torsen-b", "--analytic-only", "--set", "gears.damping_ratio=inf"],
     "torsen-b", "gears.damping_ratio"),
    (["tdr", "torsen-b", "--analytic-only", "--set", "gears.teeth_side=true"],
     "torsen-b", "gears.teeth_side"),
    (["tdr", "torsen-b", "--analytic-only", "--set", 'contact.law="abc"'],
     "torsen-b", "contact.law"),
    (["tdr", "torsen-b", "--analytic-only", "--set", "contact.restitution=1"],
     "torsen-b", "contact.restitution"),
    (["tdr", "torsen-b", "--analytic-only", "--set", "bench.speed_diff=0"],
     "torsen-b", "bench.speed_diff"),
    (["tdr", "torsen-b", "--analytic-only", "--set", "gears.helix_angle=0"],
     "torsen-b", "gears.helix_angle"),
    (["tdr", "torsen-c", "--analytic-only", "--set", "experiment.tdr={ a = 1 }"],
     "torsen-c", "experiment.tdr"),
    (["tdr", "torsen-c", "--analytic-only", "--set", "solver.newton.strategy=0"],
     "torsen-c", "solver.newton.strategy"),
    (["run", "torsen-c", "--t-end", "0.002", "--set", "scenario.kind=bench", "--set",
      'scenario.modes="abc"'], "torsen-c", "scenario.modes"),
    ([*VEHICLE, "--set", "road.mu.fl=inf"], "vehicle-4wd", "road.mu.fl"),
    ([*VEHICLE, "--set", "wheels.low_speed_damping=nan"], "vehicle-4wd",
     "wheels.low_speed_damping"),
    ([*VEHICLE, "--set", "differentials.bevel.profile_shift=nan", "--compare", "open"],
     "vehicle-4wd", "differentials.bevel.profile_shift"),
    (["vehicle", "--t-end", "0.002", "--set", "run.window=[0.001, 0.002]"],
     "vehicle-4wd", "run.window"),
    ([*VEHICLE, "--set", "final_drive.pressure_angle=0"], "vehicle-4wd",
     "final_drive.pressure_angle"),
    ([*VEHICLE, "--set", "differentials.bevel.profile_shift=0", "--compare", "open"],
     "vehicle-4wd", "differentials.bevel.profile_shift"),
    ([*VEHICLE, "--set", "differentials.bevel.clutch.stiffness=0", "--compare", "clutch"],
     "vehicle-4wd", "differentials.bevel.clutch.stiffness"),
    ([*VEHICLE, "--set", 'wheels.tyre="simple-mud"'], "vehicle-4wd", "wheels.tyre"),
    ([*VEHICLE, "--set", "differentials.bevel.teeth_side=1e9", "--compare", "open"],
     "vehicle-4wd", "differentials.bevel.teeth_side"),
    ([*VEHICLE, "--set", "wheels.inertia=[0, 0, 0]"], "vehicle-4wd", "wheels.inertia"),
    (["run", "torsen-b", "--t-end", "0.002", "--set", "bodies.housing.inertia=[1, 1, 5]"],
     "torsen-b", "bodies.housing.inertia"),
    (["run", "torsen-c", "--t-end", "0.002", "--set", "solver.output_dt=1e-11"],
     "torsen-c", "solver.output_dt"),
    ([*VEHICLE, "--set", "load.ramp=1e-300"], "vehicle-4wd", "load.ramp"),
    (["run", "torsen-b", "--t-end", "0.002", "--set", "vehicle.ramp=1e-12", "--set",
      "vehicle.hold=1e5"], "torsen-b", "vehicle.ramp"),
    (["tdr", "torsen-b", "--analytic-only", "--set", "gears.module=1e-300"], "torsen-b",
     "gears.module"),
    (["tdr", "torsen-b", "--analytic-only", "--set",
      "contact.elastic_washers.youngs_modulus=1e-300"], "torsen-b",
     "contact.elastic_washers.youngs_modulus"),
    (["tdr", "torsen-c", "--analytic-only", "--set", "flexible.density=1e-300"], "torsen-c",
     "flexible.density"),
    (["tdr", "torsen-c", "--analytic-only", "--set", "gears.helix_angle=1e-300"], "torsen-c",
     "gears.helix_angle"),
]


@pytest.mark.parametrize("args, source, key", REGRESSIONS,
                         ids=[" ".join(a[-2:]) for a, _, _ in REGRESSIONS])
def test_holes_found_by_fuzzing_stay_closed(args: list[str], source: str, key: str) -> None:
    """Each input that once crashed (internal error) or was refused without naming the
    file and the key: now exit 2 naming both. Fails if one of the fixes is undone."""
    out = cli(args)
    check_outcome(out, source, key)
    assert out.exit_code == 2, out.show()


def test_road_friction_zero_and_analytic_failure_run(tmp_path: Path) -> None:
    """Valid values that once crashed: a road friction of 0 under a wheel (the tyre formula
    divided by zero) runs; pockets.mu = 1 (no sliding equilibrium in the analytic model) is a
    failed evaluation, exit 1 with the reason. Fails if either becomes an internal error."""
    out = cli([*VEHICLE, "--set", "road.mu.fl=0"])
    assert_clean(out)
    assert out.exit_code in (0, 1), out.show()
    out = cli(["tdr", "torsen-b", "--analytic-only", "--set", "pockets.mu=1"])
    assert_clean(out)
    assert out.exit_code == 1 and "analytic model failed" in out.text, out.show()


def test_vehicle_names_its_key_for_an_impossible_torsen_file(tmp_path: Path) -> None:
    """A vehicle whose ``differentials.torsen_b`` file has an impossible geometry is refused
    before the build, naming the vehicle file, its key and the TORSEN file's key (fails if
    the TORSEN file is only checked inside the build, whose message names neither)."""
    from drivedyn.config.loader import shipped_models

    text = shipped_models()["torsen-b"].read_text()
    assert "teeth_element = 12" in text
    bad = tmp_path / "torsen-b-bad.toml"
    bad.write_text(text.replace("teeth_element = 12", "teeth_element = 40"))
    for args in ([*VEHICLE, "--set", f'differentials.torsen_b="{bad}"'],
                 ["run", "vehicle-4wd", "--t-end", "0.002", "--out", str(tmp_path / "v.nc"),
                  "--set", f'differentials.torsen_b="{bad}"']):
        out = cli(args)
        check_outcome(out, "vehicle-4wd", "differentials.torsen_b")
        assert out.exit_code == 2 and "gears.teeth_element = 40" in out.text, out.show()


# -- long profile -----------------------------------------------------------------------------

@pytest.mark.fuzz_long
@long(600)
@given(model=st.sampled_from(["torsen-c", "torsen-b"]), data=st.data())
def test_differential_files_long(tmp_path: Path, model: str, data: st.DataObject) -> None:
    """Long profile of the differential tests (every accepted value also simulated, in the
    vehicle or the bench scenario). Fails on their mutations, and e.g. if the bench's
    ``scenario.modes`` check is removed (the builder's message names no key)."""
    key, value = data.draw(overrides(model))
    run_differential(tmp_path, model, key, value, simulate=True, bench=data.draw(st.booleans()))


@pytest.mark.fuzz_long
@long(300)
@given(model=st.sampled_from(sorted(MODELS)), data=st.data())
def test_several_keys_at_once_long(tmp_path: Path, model: str, data: st.DataObject) -> None:
    """Two or three keys at edge values together (interactions: a window and an end time, a
    module and a clearance...): clean outcome; a refusal names the file and one of the
    keys. Fails e.g. if a geometry check's message stops naming the other keys it depends on
    (pockets overlap without pockets.clearance)."""
    sets = [data.draw(overrides(model)) for _ in range(data.draw(st.integers(2, 3)))]
    args = [a for k, v in sets for a in ("--set", f"{k}={v}")]
    if model == "vehicle-4wd":
        out = cli([*VEHICLE, *args])
    else:
        out = cli(["tdr", model, "--analytic-only", *args])
        if out.exit_code != 2:
            out = cli(["run", model, "--t-end", "0.002", "--out", str(tmp_path / "r.nc"),
                       *args])
    assert_clean(out)
    if out.exit_code == 2:
        msg = out.text[out.text.index("error: "):]
        assert model in msg, out.show()
        assert any(_names_key(msg, k) for k, _ in sets), out.show()


FLEXIBLE_KEYS = [(k, a) for k, a in KEYS["torsen-c"] if k.startswith("flexible.")
                 and k not in ("flexible.washers", "flexible.case")]


@pytest.mark.fuzz_long
@long(40)
@given(data=st.data())
def test_flexible_parts_long(tmp_path: Path, drivedyn_cache: Path, data: st.DataObject) -> None:
    """The Type C with its meshed flexible washers or case (Craig-Bampton reductions, cached
    in the test's own folder) and one key of ``[flexible]`` at an edge value, 2 ms: clean
    outcome. Fails e.g. if a modulus of 1e-300 Pa reaches the mesh (the plausibility floor of
    moduli removed)."""
    part = data.draw(st.sampled_from(["washers", "case"]))
    key, annotation = data.draw(st.sampled_from(FLEXIBLE_KEYS))
    value = data.draw(edge_value(annotation))
    out = cli(["run", "torsen-c", "--t-end", "0.002", "--out", str(tmp_path / "f.nc"),
               "--set", f"flexible.{part}=true", "--set", f"{key}={value}"])
    check_outcome(out, "torsen-c", key)


@pytest.mark.fuzz_long
@long(300)
@given(data=st.data())
def test_vehicle_file_long(data: st.DataObject) -> None:
    """Long profile of :func:`test_vehicle_file_refuses_or_runs` (fails on the same
    mutations, e.g. the schema's inertia check removed: the builder names the body, not
    the key)."""
    key, value = data.draw(overrides("vehicle-4wd"))
    config = data.draw(st.sampled_from([None, "open", "clutch", "locked"]))
    run_vehicle(key, value, config)


@pytest.mark.fuzz_long
@long(150)
@given(data=st.data())
def test_vehicle_file_runs_long(data: st.DataObject) -> None:
    """Long profile of :func:`test_vehicle_file_runs_or_fails_cleanly` (fails on the same
    mutations, e.g. the window analysis dividing by a zero engine torque again)."""
    key, value = data.draw(accepted_overrides("vehicle-4wd"))
    config = data.draw(st.sampled_from([None, "open", "clutch", "locked"]))
    run_vehicle(key, value, config)


@pytest.mark.fuzz_long
@long(150)
@given(model=st.sampled_from(["torsen-c", "torsen-b"]), data=st.data())
def test_differential_files_run_long(tmp_path: Path, model: str, data: st.DataObject) -> None:
    """Long profile of :func:`test_differential_files_run_or_fail_cleanly`, vehicle and
    bench scenarios (fails on the same mutations)."""
    key, value = data.draw(accepted_overrides(model))
    run_differential(tmp_path, model, key, value, simulate=True,
                     bench=data.draw(st.booleans()))


def _vehicle_problem(key: str, value: str) -> str | None:
    """Read, check and build (no simulation) the vehicle with ``key = value`` (with the open
    and clutch differentials for a bevel key): None, or what went wrong."""
    from drivedyn.analysis.vehicle_4wd import configure
    from drivedyn.config import read_library_file
    from drivedyn.config.loader import ModelFileError, read_vehicle_differentials
    from drivedyn.errors import ModelError
    from drivedyn.library import vehicles
    from drivedyn.units import UnitError

    try:
        p, _, _ = read_library_file("vehicle-4wd", [f"{key}={value}"])
        torsen = read_vehicle_differentials(p, "vehicle-4wd", Path("."))
        configs = ["open", "clutch"] if key.startswith("differentials.bevel") else [None]
        for config in configs:
            q = configure(p, config) if config else p
            vehicles.get(q.model.library).build_spec(q, torsen)
    except ModelFileError as exc:  # names the file
        return None if _names_key(str(exc), key) else f"{key}={value}: {exc}"
    except (ModelError, UnitError) as exc:  # the command prefixes the file
        return None if _names_key(str(exc), key) else f"{key}={value}: {exc}"
    except Exception as exc:
        return f"{key}={value}: {type(exc).__name__}: {exc}"
    return None


@pytest.mark.fuzz_long
@pytest.mark.parametrize("model", sorted(MODELS))
def test_every_key_and_edge_value(model: str) -> None:
    """Every key of the file with every edge value through the validation path (the
    differentials' ``tdr --analytic-only``, the vehicle's build without simulation): a
    refusal names the file and the key, nothing crashes. Fails if any check is loosened
    (e.g. ``allow_inf_nan`` dropped from the sections: an infinite damping ratio reaches the
    gear element, whose message names the mesh) or a message stops naming its key."""
    problems = []
    for key, _ in KEYS[model]:
        for value in EDGES:
            if model == "vehicle-4wd":
                problem = _vehicle_problem(key, value)
                if problem:
                    problems.append(problem)
                continue
            try:
                run_differential(Path("."), model, key, value, simulate=False)
            except AssertionError as exc:
                problems.append(str(exc))
    assert not problems, "\n\n".join(problems[:40])
