"""Fuzzing the command line with random models (hypothesis).

* Valid small models -- a chain of 1-3 rigid bodies on random joints, springs, a plane
  contact, a spur gear pair on two hinged wheels with a torque, all in ``[[elements]]`` --
  either run (exit 0) or fail cleanly (exit 1, a message, partial results): never a
  traceback or an internal error.
* Malformed models -- one random mutation of a valid model (a wrong type, a non-physical
  value, a unit of the wrong dimension, a reference to nothing, a duplicate name, a misspelt
  key, bad time settings) -- exit with 2 and a message naming the file.

The default profile (CI) tries a few dozen models; ``pytest -m fuzz_long`` runs the long
profile (several hundred).
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from drivedyn.cli import main
from fuzz_common import LONG, SHORT, to_toml

AXES = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}
JOINTS = ["Hinge", "Spherical", "Cylindrical", "Prismatic", "Fixed"]


# -- valid models ---------------------------------------------------------------------------

@st.composite
def valid_models(draw: Any) -> dict:
    nb = draw(st.integers(1, 3))
    gravity = draw(st.sampled_from([[0, 0, -9.81], [0, -9.81, 0], [0, 0, 0]]))
    bodies, markers, joints = [], [], []
    for i in range(nb):
        j1 = draw(st.floats(0.01, 1.0))
        j2 = draw(st.floats(0.01, 1.0))
        j3 = draw(st.floats(abs(j1 - j2) + 1e-3, j1 + j2))     # triangle inequality
        bodies.append({"name": f"b{i}", "mass": f"{draw(st.floats(0.1, 10.0)):.6g} kg",
                       "inertia": [j1, j2, j3], "position": [0.3 * i, 0, 0]})
        # joint at x = 0.3 i - 0.15 between the previous body (or ground) and this one
        parent = "ground" if i == 0 else f"b{i - 1}"
        axis = AXES[draw(st.sampled_from(sorted(AXES)))]
        pa = [0.3 * i - 0.15, 0, 0] if parent == "ground" else [0.15, 0, 0]
        markers += [{"name": f"j{i}a", "body": parent, "position": pa, "axis": axis},
                    {"name": f"j{i}b", "body": f"b{i}", "position": [-0.15, 0, 0],
                     "axis": axis}]
        joints.append({"type": draw(st.sampled_from(JOINTS)), "name": f"joint{i}",
                       "marker_a": f"j{i}a", "marker_b": f"j{i}b"})
    # every element in [[elements]]: the joints first (the mutations find joint0 there)
    elements: list[dict[str, Any]] = joints
    model: dict[str, Any] = {"model": {"name": "fuzz", "gravity": gravity},
                             "bodies": bodies, "markers": markers, "elements": elements}
    if draw(st.booleans()):
        markers.append({"name": "anchor", "body": "ground", "position": [0.3 * nb, 0.2, 0]})
        markers.append({"name": "tip", "body": f"b{nb - 1}", "position": [0.15, 0, 0]})
        elements.append({"type": "SpringDamper", "name": "spring", "marker_a": "anchor",
                         "marker_b": "tip",
                         "stiffness": f"{draw(st.floats(1.0, 1e4)):.6g} N/m",
                         "damping": draw(st.floats(0.0, 10.0))})
    if draw(st.booleans()):
        markers.append({"name": "floor", "body": "ground", "position": [0, 0, -0.05]})
        markers.append({"name": "probe", "body": "b0"})
        elements.append({"type": "PlaneContact", "name": "floor_contact", "marker_a": "floor",
                         "marker_b": "probe",
                         "law": {"stiffness": draw(st.floats(1e5, 1e8)), "exponent": 1.5,
                                 "law": "hunt-crossley",
                                 "restitution": draw(st.floats(0.3, 0.95))}})
    if draw(st.booleans()):
        za, zb = draw(st.integers(18, 40)), draw(st.integers(18, 60))
        mod = draw(st.sampled_from([1.5, 2.0, 3.0]))
        centre = mod * (za + zb) / 2 * 1e-3
        for g, x in (("ga", 0.0), ("gb", centre)):
            bodies.append({"name": g, "mass": 1.0, "inertia": [1e-3, 1e-3, 2e-3],
                           "position": [x, 1.0, 0]})
            markers += [{"name": f"{g}_pin", "body": "ground", "position": [x, 1.0, 0]},
                        {"name": f"{g}_hub", "body": g}]
            elements.append({"type": "Hinge", "name": f"{g}_hinge", "marker_a": f"{g}_pin",
                             "marker_b": f"{g}_hub"})
        elements.append({"type": "GearPair", "name": "mesh", "marker_a": "ga_hub",
                         "marker_b": "gb_hub", "teeth_a": za, "teeth_b": zb,
                         "module": f"{mod} mm", "face_width": "15 mm"})
        elements.append({"type": "Torque", "name": "drive", "marker": "ga_hub",
                         "vector": [0, 0, 1],
                         "function": {"type": "ramp", "t0": 0, "t1": 0.01, "v0": 0,
                                      "v1": draw(st.floats(0.1, 20.0))}})
    model["solver"] = {"t_end": "20 ms", "rho_inf": 0.8, "step": {"mode": "fixed", "h": "1 ms"}}
    model["output"] = {"dt": "5 ms"}
    return model


def _run(tmp_path: Path, model: dict, name: str) -> Any:
    path = tmp_path / f"{name}.toml"
    path.write_text(to_toml(model))
    res = CliRunner().invoke(main, ["run", str(path), "--out", str(tmp_path / f"{name}.nc")])
    return res, path, res.output + res.stderr


def _no_crash(text: str) -> None:
    assert "Traceback" not in text and "internal error" not in text, text


def _check_valid(tmp_path: Path, model: dict) -> None:
    res, _, text = _run(tmp_path, model, "valid")
    _no_crash(text)
    assert res.exit_code in (0, 1), f"exit {res.exit_code}: {text}\n{to_toml(model)}"
    if res.exit_code == 1:
        assert "stopped at t =" in text


@SHORT
@given(model=valid_models())
def test_valid_models_run_or_fail_cleanly(tmp_path: Path, model: dict) -> None:
    _check_valid(tmp_path, model)


# -- malformed models: one mutation of a valid model ------------------------------------------

def _mutations(model: dict) -> list[tuple[str, Any]]:
    """(label, function mutating a deep copy) pairs applicable to ``model``."""
    def body(key: str, value: Any):
        return lambda m: m["bodies"][0].__setitem__(key, value)

    muts: list[tuple[str, Any]] = [
        ("negative mass", body("mass", -1.0)),
        ("zero mass", body("mass", 0)),
        ("NaN mass", body("mass", math.nan)),
        ("mass in metres", body("mass", "2 m")),
        ("mass not a number", body("mass", "heavy")),
        ("inertia breaks the triangle inequality", body("inertia", [1.0, 1.0, 5.0])),
        ("negative inertia", body("inertia", [1.0, -1.0, 1.0])),
        ("absurd position", body("position", [1e9, 0, 0])),
        ("zero rotation axis", body("rotation", {"axis": [0, 0, 0], "angle": 1.0})),
        ("unknown body key", body("colour", "red")),
        ("body without a name", lambda m: m["bodies"][0].pop("name")),
        ("duplicate body", lambda m: m["bodies"].append(copy.deepcopy(m["bodies"][0]))),
        ("marker on nothing", lambda m: m["markers"][1].__setitem__("body", "nowhere")),
        ("joint on nothing", lambda m: m["elements"][0].__setitem__("marker_a", "nothing")),
        ("misspelt joint type", lambda m: m["elements"][0].__setitem__("type", "Hing")),
        ("misspelt joint key", lambda m: m["elements"][0].__setitem__("markr_b", "j0b")),
        ("duplicate joint", lambda m: m["elements"].append(copy.deepcopy(m["elements"][0]))),
        ("end time zero", lambda m: m["solver"].__setitem__("t_end", 0)),
        ("step zero", lambda m: m["solver"].__setitem__("step", {"mode": "fixed", "h": 0})),
        ("step in kilograms", lambda m: m["solver"].__setitem__("step",
                                                                {"mode": "fixed", "h": "1 kg"})),
        ("h_min above h_max", lambda m: m["solver"].__setitem__(
            "step", {"mode": "adaptive", "h0": 1e-3, "h_min": 1e-2, "h_max": 1e-3})),
        ("infinite tolerance", lambda m: m["solver"].__setitem__("newton", {"tol": math.inf})),
        ("rho_inf a string", lambda m: m["solver"].__setitem__("rho_inf", "high")),
        ("gravity NaN", lambda m: m["model"].__setitem__("gravity", [0, 0, math.nan])),
        ("misspelt section", lambda m: m.__setitem__("solvr", m.pop("solver"))),
    ]
    for i, e in enumerate(model["elements"]):
        if e["type"] == "SpringDamper":
            muts.append(("negative stiffness",
                         lambda m, i=i: m["elements"][i].__setitem__("stiffness", -5.0)))
            muts.append(("stiffness in kg",
                         lambda m, i=i: m["elements"][i].__setitem__("stiffness", "5 kg")))
        if e["type"] == "PlaneContact":
            muts.append(("restitution above 1", lambda m, i=i: m["elements"][i]["law"]
                         .__setitem__("restitution", 1.5)))
            muts.append(("unknown element type",
                         lambda m, i=i: m["elements"][i].__setitem__("type", "PlainContact")))
        if e["type"] == "GearPair":
            muts.append(("fractional tooth count",
                         lambda m, i=i: m["elements"][i].__setitem__("teeth_a", 20.5)))
            muts.append(("module in seconds",
                         lambda m, i=i: m["elements"][i].__setitem__("module", "2 s")))
            muts.append(("gear centre distance off",
                         lambda m, i=i: m["elements"][i].__setitem__("teeth_b", 90)))
    return muts


@st.composite
def malformed_models(draw: Any) -> tuple[str, dict]:
    model = draw(valid_models())
    label, mutate = draw(st.sampled_from(_mutations(model)))
    bad = copy.deepcopy(model)
    mutate(bad)
    return label, bad


def _check_malformed(tmp_path: Path, case: tuple[str, dict]) -> None:
    label, model = case
    res, path, text = _run(tmp_path, model, "bad")
    _no_crash(text)
    assert res.exit_code == 2, f"{label}: exit {res.exit_code}: {text}\n{to_toml(model)}"
    assert str(path) in text, f"{label}: the message does not name the file: {text}"
    assert not list(tmp_path.glob("*.nc"))


@SHORT
@given(case=malformed_models())
def test_malformed_models_exit_2(tmp_path: Path, case: tuple[str, dict]) -> None:
    _check_malformed(tmp_path, case)


def test_every_mutation_is_refused(tmp_path: Path) -> None:
    """Each mutation once, on a model that has every optional part (so none is skipped by
    chance in the short profile)."""
    full = _full_model()
    for label, mutate in _mutations(full):
        bad = copy.deepcopy(full)
        mutate(bad)
        _check_malformed(tmp_path, (label, bad))


def _full_model() -> dict:
    """A deterministic valid model with a spring, a contact and a gear pair."""
    from hypothesis import find

    def full(m: dict) -> bool:
        return {"SpringDamper", "PlaneContact", "GearPair"} <= {e["type"] for e in m["elements"]}

    return find(valid_models(), full, settings=settings(database=None, max_examples=2000))


@pytest.mark.fuzz_long
@LONG
@given(model=valid_models())
def test_valid_models_long(tmp_path: Path, model: dict) -> None:
    _check_valid(tmp_path, model)


@pytest.mark.fuzz_long
@LONG
@given(case=malformed_models())
def test_malformed_models_long(tmp_path: Path, case: tuple[str, dict]) -> None:
    _check_malformed(tmp_path, case)
