"""Tests of the command line interface (``drivedyn validate``, ``--version``, ``--help``).

The validation registry is replaced by fake cases, so these tests do not depend on (or run)
the real validation cases.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

import drivedyn
import drivedyn.validation
from drivedyn.cli import main
from drivedyn.validation import base
from drivedyn.validation.base import compare


def _good(quick: bool = False, figure_dir: str | None = None) -> list[base.CaseResult]:
    res = [compare("good", "period", 2.0, 2.0 + 1e-7, "s", 1e-6, source="exact formula"),
           compare("good", "energy drift", 0.0, 1e-9, "J", 1e-6)]
    if figure_dir is not None:
        fig = Path(figure_dir) / "good.png"
        fig.write_bytes(b"\x89PNG\r\n\x1a\n")  # a stand-in for a figure
        res[0].figures.append(str(fig))
    return res


def _bad(quick: bool = False, figure_dir: str | None = None) -> list[base.CaseResult]:
    return [compare("bad", "peak torque | ratio", 100.0, 150.0, "N m", 0.01)]


def _raises(quick: bool = False, figure_dir: str | None = None) -> list[base.CaseResult]:
    raise RuntimeError("solver exploded")


@pytest.fixture
def fake_cases(monkeypatch: pytest.MonkeyPatch) -> dict:
    """Replace the case registry (the real cases are not run) and run the cases in this
    process (a case process would import the real registry)."""
    import importlib

    registry = {"good": _good, "bad": _bad, "raises": _raises}
    monkeypatch.setattr(drivedyn.validation, "CASES", registry)
    monkeypatch.setattr(importlib.import_module("drivedyn.cli.validate"), "default_jobs",
                        lambda: 1)
    return registry


def test_version(runner: CliRunner) -> None:
    res = runner.invoke(main, ["--version"])
    assert res.exit_code == 0
    assert drivedyn.__version__ in res.stdout


def test_help(runner: CliRunner) -> None:
    res = runner.invoke(main, ["--help"])
    assert res.exit_code == 0
    assert "validate" in res.stdout
    assert "Example" in res.stdout
    res = runner.invoke(main, ["validate", "--help"])
    assert res.exit_code == 0
    for opt in ("--quick", "--case", "--report", "--json", "--jobs"):
        assert opt in res.stdout


def test_validate_pass(runner: CliRunner, fake_cases: dict) -> None:
    res = runner.invoke(main, ["validate", "--case", "good"])
    assert res.exit_code == 0, res.output
    assert "PASS" in res.stdout
    assert "FAIL" not in res.stdout
    assert "2 of 2 checks passed" in res.stdout


def test_validate_fail_exit_code(runner: CliRunner, fake_cases: dict) -> None:
    res = runner.invoke(main, ["validate", "--case", "good", "--case", "bad"])
    assert res.exit_code == 1, res.output
    assert "FAIL" in res.stdout
    assert "PASS" in res.stdout


def test_validate_all_cases_and_exception(runner: CliRunner, fake_cases: dict) -> None:
    res = runner.invoke(main, ["validate", "--quick"])
    assert res.exit_code == 1, res.output
    assert "solver exploded" in res.stdout  # a raising case is a failure, others still run
    assert "good" in res.stdout and "bad" in res.stdout


def test_validate_json(runner: CliRunner, fake_cases: dict) -> None:
    res = runner.invoke(main, ["validate", "--json"])
    assert res.exit_code == 1
    data = json.loads(res.stdout)  # stdout holds only the JSON (strict: no NaN/Infinity)
    assert [d["case"] for d in data] == ["good", "good", "bad", "raises"]
    assert [d["passed"] for d in data] == [True, True, False, False]
    assert data[0]["reference"] == 2.0 and data[0]["unit"] == "s"
    assert data[3]["error"] is None and "solver exploded" in data[3]["source"]
    assert {"quantity", "simulated", "error", "tolerance", "wall_s", "figures"} <= set(data[0])

    res = runner.invoke(main, ["validate", "--json", "--case", "good"])
    assert res.exit_code == 0
    assert all(d["passed"] for d in json.loads(res.stdout))


def test_validate_report(runner: CliRunner, fake_cases: dict, tmp_path: Path) -> None:
    out = tmp_path / "rep"
    res = runner.invoke(main, ["validate", "--case", "good", "--case", "bad",
                               "--report", str(out)])
    assert res.exit_code == 1, res.output
    text = (out / "report.md").read_text()
    assert "| case | quantity |" in text
    assert "**FAIL**" in text and "PASS" in text
    assert "peak torque \\| ratio" in text  # pipes in cells are escaped
    assert "](good.png)" in text  # figure linked relative to the report
    assert (out / "good.png").exists()
    assert "1 of 3 checks passed" not in text and "2 of 3 checks passed" in text


def test_unknown_case_is_usage_error(runner: CliRunner, fake_cases: dict) -> None:
    res = runner.invoke(main, ["validate", "--case", "nope"])
    assert res.exit_code == 2
    assert "nope" in res.stderr and "good" in res.stderr


def test_bad_option_is_usage_error(runner: CliRunner) -> None:
    assert runner.invoke(main, ["validate", "--no-such-option"]).exit_code == 2
    assert runner.invoke(main, ["no-such-command"]).exit_code == 2


def test_no_cases_registered(runner: CliRunner, fake_cases: dict,
                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(drivedyn.validation, "CASES", {})
    res = runner.invoke(main, ["validate"])
    assert res.exit_code == 0
    assert "no validation cases" in res.stderr
    res = runner.invoke(main, ["validate", "--json"])
    assert res.exit_code == 0
    assert json.loads(res.stdout) == []


def test_command_line_starts_without_the_numerical_stack() -> None:
    """`drivedyn --help` and the command tree load neither numba, scipy nor xarray (the
    package exports its names lazily; the commands import what they run): the cold start of
    the command line is the import of click and numpy only."""
    import subprocess
    import sys

    code = ("import sys, drivedyn.cli, drivedyn; "
            "print(sorted(m for m in ('numba', 'scipy', 'xarray', 'matplotlib') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"
    # the lazy exports resolve to the defining modules' objects
    import drivedyn
    from drivedyn.solver import simulate

    assert drivedyn.simulate is simulate
    # every exported name resolves, to the object of the module it is defined in
    for name in drivedyn.__all__:
        obj = getattr(drivedyn, name)
        if hasattr(obj, "__module__") and not isinstance(obj, str | int | float):
            assert obj.__module__.startswith("drivedyn."), (name, obj.__module__)
    assert set(drivedyn.__all__) <= set(dir(drivedyn))
    with pytest.raises(AttributeError, match="no_such_name"):
        drivedyn.no_such_name  # noqa: B018


def test_dense_lu_calls_scipys_lapack() -> None:
    """The compiled dense LU calls LAPACK by the names registered with LLVM when
    drivedyn.solver.lapack is imported: those names resolve to SciPy's own ``dgetrf`` and
    ``dgetrs`` (numba's public ``get_cython_function_address``). Registering another
    function's address (e.g. dgetrs for dgetrf) makes it fail."""
    import llvmlite.binding as llb
    from numba.extending import get_cython_function_address

    import drivedyn.solver.lapack  # noqa: F401 - registers the symbols

    for name in ("dgetrf", "dgetrs"):
        addr = get_cython_function_address("scipy.linalg.cython_lapack", name)
        assert addr != 0 and llb.address_of_symbol(f"drivedyn_{name}") == addr


def test_validate_in_case_processes_equals_one_process(runner: CliRunner,
                                                       tmp_path: Path) -> None:
    """Four real cases in two processes (``--jobs 2``) give the figures of one process
    (``--jobs 1``), in the order asked for, with a case's figure written by its process and
    linked from the report. The cases are submitted last-asked first, so the three short
    ones (0.2 s each) end before the pendulum (1.6 s), asked for first: a table built in
    order of completion (``outcome`` in ``_run``) fails the order (seen); results assigned
    to the wrong case fail the figures. The
    processes differ from this one only by their single BLAS thread, which does not change
    these small models' LU: the figures are compared exactly."""
    args = ["validate", "--quick", "--json"]
    for name in ("pendulum", "heavy_top", "convergence", "bouncing_ball"):
        args += ["--case", name]
    one = runner.invoke(main, [*args, "--jobs", "1"])
    two = runner.invoke(main, [*args, "--jobs", "2", "--report", str(tmp_path / "rep")])
    assert one.exit_code == 0 and two.exit_code == 0, one.output + two.output
    serial, parallel = json.loads(one.stdout), json.loads(two.stdout)
    assert [(d["case"], d["quantity"], d["simulated"]) for d in parallel] == \
        [(d["case"], d["quantity"], d["simulated"]) for d in serial]
    assert parallel[0]["case"] == "pendulum"
    figures = [f for d in parallel if d["case"] == "bouncing_ball" for f in d["figures"]]
    assert figures and all(Path(f).exists() for f in figures)
    assert Path(figures[0]).name in (tmp_path / "rep" / "report.md").read_text()
