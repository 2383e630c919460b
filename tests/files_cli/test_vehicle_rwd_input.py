"""Bad input to the RWD vehicle through its model file and the command line: each is refused
with exit code 2 by ``drivedyn vehicle vehicle-rwd`` and by ``drivedyn run vehicle-rwd``,
before anything is simulated or written, the message naming the key and the value, no
traceback. The suspension set is changed the two ways a user does: ``--set
suspension_overrides.<key of the suspension file>=...`` and a user suspension file
(``--set suspensions=<path>``); tyre files are written beside the test."""

from __future__ import annotations

import re

import pytest
from click.testing import CliRunner

from drivedyn.cli import main
from drivedyn.config import read_library_file
from drivedyn.library.vehicles.suspensions import SHIPPED
from drivedyn.library.vehicles.vehicle_rwd import load_tyre, measured_side, tyre_notes
from drivedyn.tyres import read_tir, shipped, side_asymmetry

TYRE = "hmmwv_pac02_37x12.5R16.5"
#: the shipped front upper arm's front pickup [m] to 6 digits (Chrono's -1.8864, 17.5575,
#: 9.6308 in): the rear pickup put there leaves the arm no pivot axis
UPPER_ARM_FRONT = "[-0.0479146, 0.44596, 0.244622]"


def _tyre_file(tmp_path, side: str | None):
    """The shipped tyre file with ``[MODEL] TYRESIDE`` set to ``side`` (None: removed)."""
    text = shipped(TYRE).read_text()
    line = re.search(r"(?m)^TYRESIDE.*\n", text).group(0)
    new = "" if side is None else f"TYRESIDE = '{side.upper()}'\n"
    path = tmp_path / f"tyre_{side or 'unsided'}.tir"
    path.write_text(text.replace(line, new))
    return path


def _suspension_file(tmp_path):
    """The shipped suspension set with the rear axle's type changed."""
    path = tmp_path / "my_suspensions.toml"
    text = SHIPPED["hmmwv"].read_text()
    path.write_text(text.replace('[rear]\ntype = "double_wishbone"', '[rear]\ntype = "multi_link"',
                                 1))
    return path


#: id -> (overrides, key and value the message must name); ``<name>`` is a file the test
#: writes first
CASES = {
    "zero-length link": (
        [f"suspension_overrides.front.hardpoints.upper_arm_rear={UPPER_ARM_FRONT}"],
        "suspension_overrides.front.hardpoints.upper_arm_rear", UPPER_ARM_FRONT),
    "non-monotone spring table": (
        ["suspension_overrides.rear.spring.curve=[[-0.1, -5000.0], [0.0, 0.0], [0.1, -1000.0]]"],
        "suspension_overrides.rear.spring.curve", "[[-0.1, -5000.0], [0.0, 0.0], [0.1, -1000.0]]"),
    "negative free length": (
        ['suspension_overrides.front.spring.free_length="-0.339 m"'],
        "suspension_overrides.front.spring.free_length", "-0.339 m"),
    "wheel not on a hub": (
        ["suspension_overrides.rear.hardpoints.wheel_center=[0.03556, 0.508, -0.026289]"],
        "suspension_overrides.rear.hardpoints.wheel_center", "[0.03556, 0.508, -0.026289]"),
    "unknown suspension type": (
        ['suspensions="<suspensions>"'], "rear.type", "multi_link"),
    "asymmetric tyre file without a side": (
        ['wheels.tyre="<unsided>"'], "wheels.tyre", "tyre_unsided.tir"),
    "right-side tyre file declared left": (
        ['wheels.tyre="<right>"', 'wheels.tyre_side="left"'], "wheels.tyre_side", "'left'"),
    "steering beyond the rack travel": (
        ['steering.pinion_angle={type="smooth_step", t0=0.5, t1=1.0, v0=0.0, v1=0.6}'],
        "steering.pinion_angle", "0.6 rad"),
}


@pytest.mark.parametrize("command", ["vehicle", "run"])
@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_exits_2_naming_key_and_value(case, command, tmp_path):
    """Mutations that fail it: drop the geometry check of ``inputs.vehicle_suspensions``
    (the zero-length arm and the inboard wheel are built; exit 0 or a solver failure), the
    monotone check of the suspension tables, the steering check, the tyre side rules; name
    the suspension file's key without ``suspension_overrides``."""
    sets, key, value = CASES[case]
    files = {"suspensions": _suspension_file(tmp_path), "unsided": _tyre_file(tmp_path, None),
             "right": _tyre_file(tmp_path, "right")}
    out = tmp_path / ("out" if command == "vehicle" else "out.nc")
    args = [command, "vehicle-rwd", "--t-end", "0.05", "--out", str(out)]
    if command == "vehicle":
        args += ["--scenario", "static"]
    for s in sets:
        for name, path in files.items():
            s = s.replace(f"<{name}>", str(path))
        args += ["--set", s]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    message = r.output.split("error: ", 1)[1]
    assert key in message and value in message, message
    assert "simulating" not in r.output  # refused before any work
    assert not out.exists()


def test_a_file_measured_on_one_side_is_mirrored_for_the_other_with_a_note(tmp_path):
    """The serious reading of a tyre file's side: its ``[MODEL] TYRESIDE`` is used, the tyre
    mirrored for the wheels on the other side and a note says so; a file without it is used
    on both sides as it is only when its tyre is symmetric, else ``wheels.tyre_side`` must
    say where it was measured.

    Mutations: mirror for the file's own side (the right wheels get a mirrored right-side
    file); accept an asymmetric file without a side (no exit 2 above)."""
    right = _tyre_file(tmp_path, "right")
    p, _, _ = read_library_file("vehicle-rwd", [f'wheels.tyre="{right}"'])
    assert measured_side(p) == "right"
    assert "mirrored" in load_tyre(p, ".", "left").name
    assert "mirrored" not in load_tyre(p, ".", "right").name
    (note,) = tyre_notes(p)
    assert "measured on the right" in note and "mirrored for the left wheels" in note
    unsided = _tyre_file(tmp_path, None)
    assert side_asymmetry(read_tir(unsided)) > 0.05  # the HMMWV tyre pulls to one side
    q, _, _ = read_library_file("vehicle-rwd", [f'wheels.tyre="{unsided}"',
                                                'wheels.tyre_side="right"'])
    assert measured_side(q) == "right"
    assert "mirrored" in load_tyre(q, ".", "left").name
    s, _, _ = read_library_file("vehicle-rwd", [f'wheels.tyre="{unsided}"',
                                                'wheels.tyre_side="symmetric"'])
    assert "mirrored" not in load_tyre(s, ".", "left").name and not tyre_notes(s)
