"""Output paths of every command that writes files.

Before any work, an output path that cannot be written is refused: exit code 2, ``error:``
naming the option, the path and the operating system's reason, no traceback, and the
command's work never starts. After the work, a path that refuses the write anyway (here: the
output folder is replaced by a file while the command works) does not lose the results: they
go to a file of the same name in the current folder, else in the system's temporary folder,
the message names it and the exit code is 1.

The refusal tests replace each command's work by a function that raises ``_WorkStartedError``, so a
refusal that comes after the work (or never) fails them with exit code 1 and that name in the
output; they need no real model run. The fallback tests run the smallest cases (the pendulum
for 0.01 s, the analytic calibration).

A read-only folder for a process that writes through permission bits (root, or
CAP_DAC_OVERRIDE, as in containers) cannot be made with ``chmod``: there the read-only case
uses ``/sys``, a folder of the Linux kernel that refuses every new file to every user
(Permission denied) and that ``os.access`` reports writable to root. Where neither refuses,
the case is skipped with that reason.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import click
import pytest
from click.testing import CliRunner, Result

from drivedyn.cli import main
from drivedyn.cli.common import OutputFiles


def _patch(monkeypatch: pytest.MonkeyPatch, target: str,
           replace: Callable[[Callable[..., object]], Callable[..., object]]) -> None:
    """Replace ``module:attribute`` by ``replace(original)`` for the test (the module is
    imported by name: ``drivedyn.solver.simulate`` is a module, not the package's function)."""
    import importlib

    module, _, name = target.partition(":")
    mod = importlib.import_module(module)
    monkeypatch.setattr(mod, name, replace(getattr(mod, name)))


class _WorkStartedError(Exception):
    """Raised by a command's work in the refusal tests: the check came too late."""


def _refuses(folder: Path) -> bool:
    """Whether this process cannot create a file in ``folder``."""
    try:
        fd, tmp = tempfile.mkstemp(dir=folder)
    except OSError:
        return True
    os.close(fd)
    os.unlink(tmp)
    return False


@pytest.fixture
def read_only(tmp_path: Path) -> Iterator[Path]:
    """A folder that refuses new files: ``tmp/ro`` with mode 0o500, or ``/sys`` for a process
    that writes through permission bits (see the module docstring); skipped if neither."""
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        if _refuses(ro):
            yield ro
        elif sys.platform.startswith("linux") and Path("/sys").is_dir() \
                and _refuses(Path("/sys")):
            yield Path("/sys")
        else:
            pytest.skip("no folder refuses a new file to this process (root writes through "
                        "mode 0o500 and /sys is missing or writable)")
    finally:
        ro.chmod(0o700)


# every output option of every command: (command, option, folder option?, arguments before
# the option, the functions that do the command's work, which must not run when refusing)
OUTPUTS = [
    ("run", "--out", False, ["pendulum", "--t-end", "0.01"],
     ["drivedyn.config:load_model", "drivedyn.solver.simulate:simulate"]),
    ("run", "--csv", False, ["pendulum", "--t-end", "0.01"],
     ["drivedyn.config:load_model", "drivedyn.solver.simulate:simulate"]),
    ("plot", "--out", True, ["{results}"],
     ["drivedyn.cli.files:_sweep_dataset", "drivedyn.results.results:load_results"]),
    ("calibrate", "--out", False, ["torsen-c", "--no-confirm"],
     ["drivedyn.cli.differential:_params"]),
    ("bounce", "--plot", False, ["--t-end", "0.1"],
     ["drivedyn.library.bouncing_ball:run_bounce"]),
    ("vehicle", "--out", True, ["--compare", "open", "--t-end", "0.01"],
     ["drivedyn.config:read_library_file", "drivedyn.analysis.vehicle_4wd:run"]),
    ("sweep", "--out", False, ["pendulum", "--vary", "bodies.rod.mass=1,2", "--t-end", "0.01",
                               "--scheduler", "serial"], ["drivedyn.sweeps:sweep"]),
    ("sweep", "--cache", True, ["pendulum", "--vary", "bodies.rod.mass=1,2", "--t-end",
                                "0.01", "--scheduler", "serial"], ["drivedyn.sweeps:sweep"]),
    ("sweep", "--plots", True, ["pendulum", "--vary", "bodies.rod.mass=1,2", "--t-end",
                                "0.01", "--scheduler", "serial", "--no-cache"],
     ["drivedyn.sweeps:sweep"]),
    ("sweep", "--keep-runs", True, ["pendulum", "--vary", "bodies.rod.mass=1,2", "--t-end",
                                    "0.01", "--scheduler", "serial", "--no-cache"],
     ["drivedyn.sweeps:sweep"]),
    ("tdr", "--out", True, ["torsen-b", "--mode", "1"], ["drivedyn.analysis.tdr:evaluate"]),
    ("fmu", "--out", False, ["torsen-b"],
     ["drivedyn.fmu:build_fmu", "drivedyn.fmu.build:fmu_kind"]),
    ("view", "--out", False, ["{results}"], ["drivedyn.cli.view:load_scene"]),
    ("view", "--gltf", False, ["{results}"], ["drivedyn.cli.view:load_scene"]),
    ("view", "--vtk", True, ["{results}"], ["drivedyn.cli.view:load_scene"]),
    ("report", "--out", False, ["{results}"],
     ["xarray:open_dataset", "drivedyn.cli.view:load_scene"]),
    ("validate", "--report", True, ["--case", "pendulum"],
     ["drivedyn.cli.validate:_load_cases"]),
]
SUFFIX = {"--csv": ".csv", "--gltf": ".glb", "--plot": ".png", "--out": ".out"}


def _bad_path(case: str, tmp_path: Path, read_only: Callable[[], Path], option: str,
              folder: bool) -> Path:
    """The refused output path of ``case`` for a file option (a name with a suffix) or a
    folder option: under /proc, below a file, in (or, for a folder option, being) a
    read-only folder."""
    name = "out" if folder else "out" + SUFFIX[option]
    if case == "proc":
        return Path("/proc") / f"drivedyn-test-{name}"
    if case == "parent is a file":
        parent = tmp_path / "a-file"
        parent.write_text("not a folder")
        return parent / name
    ro = read_only()
    return ro if folder else ro / name


@pytest.mark.parametrize("case", ["proc", "parent is a file", "read-only folder"])
@pytest.mark.parametrize("command, option, folder, args, work", OUTPUTS,
                         ids=[f"{c} {o}" for c, o, *_ in OUTPUTS])
def test_an_output_path_that_cannot_be_written_is_refused_before_any_work(
        command: str, option: str, folder: bool, args: list[str], work: list[str], case: str,
        tmp_path: Path, request: pytest.FixtureRequest,
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Every output option of every command, with a path under /proc, a path whose parent is
    a file and a read-only folder: exit 2, ``error: OPTION PATH: ...``, no traceback, and the
    command's work (replaced by ``_WorkStartedError``) never starts.

    Deliberate mutations that fail it: ``check_output_path`` back to ``os.access`` (/proc
    and, as root, /sys pass: the work starts, exit 1 with ``_WorkStartedError``); a command that
    drops the check of one option or checks it after its work; the probe of a folder still to
    be created removed (/proc/drivedyn-test-out passes for the folder options)."""
    for target in work:
        def started(original: Callable[..., object], _name: str = target) -> Callable:
            def work(*a: object, **k: object) -> None:
                raise _WorkStartedError(_name)
            return work
        _patch(monkeypatch, target, started)
    monkeypatch.chdir(tmp_path)  # default outputs (sweep's results file) go here
    results = tmp_path / "results.nc"
    results.write_text("a stand-in: the command must refuse before reading it")
    bad = _bad_path(case, tmp_path, lambda: request.getfixturevalue("read_only"), option,
                    folder)
    before = sorted(tmp_path.iterdir())
    argv = [command, *(a.replace("{results}", str(results)) for a in args), option, str(bad)]
    res = CliRunner().invoke(main, argv)
    assert res.exit_code == 2, res.output
    assert f"error: {option} {bad}:" in res.output, res.output
    assert "_WorkStartedError" not in res.output and "Traceback" not in res.output
    assert isinstance(res.exception, SystemExit)
    assert "simulating" not in res.output
    assert sorted(tmp_path.iterdir()) == before  # nothing written, no probe left behind


def test_every_output_option_is_covered() -> None:
    """The table above lists every option of every command that names a file or folder to
    write (a ``click.Path`` option that need not exist), so a new output option is tested.

    Deliberate mutation that fails it: a new ``click.Path`` output option without a row in
    OUTPUTS, or a row removed."""
    found = set()
    for name, cmd in main.commands.items():
        for p in cmd.params:
            if isinstance(p, click.Option) and isinstance(p.type, click.Path) \
                    and not p.type.exists:
                found.add((name, p.opts[0]))
    assert found == {(c, o) for c, o, *_ in OUTPUTS}


def test_the_probe_leaves_nothing_behind(tmp_path: Path) -> None:
    """The check creates and deletes a temporary file (or folder) in the target folder and
    leaves the folder as it was; a folder still to be created is not created by the check.

    Deliberate mutations that fail it: the probe file or folder not deleted; the check
    creating the missing folders."""
    from drivedyn.cli.common import check_output_path

    check_output_path(tmp_path / "r.nc", "--out")
    check_output_path(tmp_path / "new" / "deeper", "--out", directory=True)
    check_output_path(tmp_path / "new2" / "r.nc", "--out")
    assert list(tmp_path.iterdir()) == []


# -- fallbacks after the work ------------------------------------------------------------


@pytest.fixture(scope="module")
def pendulum_results(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The results of the pendulum run for 0.01 s."""
    out = tmp_path_factory.mktemp("pendulum") / "pendulum.nc"
    res = CliRunner().invoke(main, ["run", "pendulum", "--t-end", "0.01", "--out", str(out)])
    assert res.exit_code == 0, res.output
    return out


def _sabotage(monkeypatch: pytest.MonkeyPatch, target: str, folder: Path) -> None:
    """Wrap ``target`` (``module:function``, the command's work, which runs after the output
    paths are checked): once it has run, ``folder`` is replaced by a file, so every write
    into it fails."""

    def wrap(original: Callable[..., object]) -> Callable[..., object]:
        def work(*args: object, **kwargs: object) -> object:
            value = original(*args, **kwargs)
            shutil.rmtree(folder)
            folder.write_text("the output folder was replaced by a file during the work")
            return value
        return work

    _patch(monkeypatch, target, wrap)


@pytest.fixture
def cwd(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A current folder of the test's own (where the fallbacks go)."""
    here = tmp_path / "cwd"
    here.mkdir()
    monkeypatch.chdir(here)
    return here


def _fell_back(res: Result, option: str, target: Path, fallback: Path) -> None:
    """Exit 1, the fallback message naming the option, the refused path and the fallback."""
    assert res.exit_code == 1, res.output
    assert isinstance(res.exception, SystemExit), res.output
    assert "Traceback" not in res.output and "internal error" not in res.output
    assert (f"error: could not write {option} {target} (" in res.output
            and f"written to {fallback} instead" in res.output), res.output
    assert fallback.exists(), res.output


def test_run_results_go_to_the_current_folder_when_the_out_folder_refuses_them(
        tmp_path: Path, cwd: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``run``: the output folder is replaced by a file during the simulation; the results
    (netCDF and CSV) are written into the current folder under their names, the message and
    the printed summary name them, exit code 1; the results file is a complete run.

    Deliberate mutations that fail it: the run's write not going through ``OutputFiles``
    (an internal error, exit 1 without a file); ``exit_if_failed`` removed (exit 0); the
    summary printing the refused path."""
    from drivedyn.results.results import load_results

    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.solver.simulate:simulate", out)
    res = CliRunner().invoke(main, ["run", "pendulum", "--t-end", "0.01", "--out",
                                    str(out / "p.nc"), "--csv", str(out / "p.csv")])
    _fell_back(res, "--out", out / "p.nc", cwd / "p.nc")
    _fell_back(res, "--csv", out / "p.csv", cwd / "p.csv")
    assert f"results: {cwd / 'p.nc'}" in res.output
    run = load_results(cwd / "p.nc")
    assert run.time[-1] == pytest.approx(0.01)
    assert (cwd / "p.csv").read_text().startswith("time")


def test_run_results_go_to_the_temporary_folder_when_the_current_folder_is_gone(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``run`` from inside the output folder, which is removed (and replaced by a file)
    during the simulation: the current folder cannot take the results either, so they go to
    the system's temporary folder, beside an older file of the same name that they do not
    replace.

    Deliberate mutations that fail it: no temporary-folder fallback (the output is lost,
    exit 1 without a file); a fallback that replaces an existing file (``p.nc`` keeps its
    old content only if the fallback is ``p-1.nc``); ``Path.cwd()`` failure not handled (an
    internal error)."""
    from drivedyn.results.results import load_results

    out = tmp_path / "out"
    out.mkdir()
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    (tmp / "p.nc").write_text("an older file")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    monkeypatch.chdir(out)
    _sabotage(monkeypatch, "drivedyn.solver.simulate:simulate", out)
    res = CliRunner().invoke(main, ["run", "pendulum", "--t-end", "0.01", "--out",
                                    str(out / "p.nc")])
    _fell_back(res, "--out", out / "p.nc", tmp / "p-1.nc")
    assert (tmp / "p.nc").read_text() == "an older file"
    assert load_results(tmp / "p-1.nc").time[-1] == pytest.approx(0.01)


def test_sweep_results_and_figures_fall_back(tmp_path: Path, cwd: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """``sweep`` (two pendulum points, in this process): the output folder is replaced by a
    file while the points run; the sweep file and the --plots figures go to the current
    folder, exit code 1.

    Deliberate mutations that fail it: the sweep's write or its figures not going through
    ``OutputFiles``; ``exit_if_failed`` removed."""
    import xarray as xr

    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.sweeps:sweep", out)
    res = CliRunner().invoke(main, [
        "sweep", "pendulum", "--vary", "bodies.rod.mass=1,2", "--metric", "hinge.angle:final",
        "--t-end", "0.01", "--scheduler", "serial", "--no-cache", "--out", str(out / "s.nc"),
        "--plots", str(out / "figs")])
    _fell_back(res, "--out", out / "s.nc", cwd / "s.nc")
    _fell_back(res, "--plots", out / "figs", cwd / "figs")
    with xr.open_dataset(cwd / "s.nc") as ds:
        assert ds.attrs["drivedyn_kind"] == "sweep" and int(ds.attrs["points"]) == 2
    assert list((cwd / "figs").glob("*.png"))


def test_view_page_gltf_and_vtk_fall_back(pendulum_results: Path, tmp_path: Path, cwd: Path,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """``view``: the output folder is replaced by a file while the scene is built; the page,
    the glTF file and the VTK folder go to the current folder, exit code 1.

    Deliberate mutation that fails it: one of the three writes not going through
    ``OutputFiles``."""
    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.cli.view:load_scene", out)
    res = CliRunner().invoke(main, ["view", str(pendulum_results), "--frames", "3", "--out",
                                    str(out / "v.html"), "--gltf", str(out / "v.glb"),
                                    "--vtk", str(out / "vtk")])
    _fell_back(res, "--out", out / "v.html", cwd / "v.html")
    _fell_back(res, "--gltf", out / "v.glb", cwd / "v.glb")
    _fell_back(res, "--vtk", out / "vtk", cwd / "vtk")
    assert "<html" in (cwd / "v.html").read_text()[:200].lower()
    assert (cwd / "v.glb").read_bytes()[:4] == b"glTF"
    assert list((cwd / "vtk").glob("*.pvd"))


def test_report_and_its_view_fall_back_and_stay_linked(
        pendulum_results: Path, tmp_path: Path, cwd: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    """``report``: the output folder is replaced by a file while the scene is built; the
    3-D view and the report go to the current folder and the report links the view where it
    is, exit code 1.

    Deliberate mutations that fail it: the report's or the view's write not going through
    ``OutputFiles``; the link computed from the refused path (``../out/...``)."""
    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.cli.view:load_scene", out)
    res = CliRunner().invoke(main, ["report", str(pendulum_results), "--out",
                                    str(out / "r-report.html")])
    _fell_back(res, "--out", out / "r-view.html", cwd / "r-view.html")
    _fell_back(res, "--out", out / "r-report.html", cwd / "r-report.html")
    assert 'href="r-view.html"' in (cwd / "r-report.html").read_text()


def test_plot_figures_fall_back(pendulum_results: Path, tmp_path: Path, cwd: Path,
                                monkeypatch: pytest.MonkeyPatch) -> None:
    """``plot``: the output folder is replaced by a file while the results are read; the
    figures go to a folder of the same name in the current folder, exit code 1.

    Deliberate mutations that fail it: the figures saved straight into ``--out`` (an
    internal error); ``exit_if_failed`` removed."""
    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.results.results:load_results", out)
    res = CliRunner().invoke(main, ["plot", str(pendulum_results), "--vars", "hinge.*",
                                    "--out", str(out / "figs")])
    _fell_back(res, "--out", out / "figs", cwd / "figs")
    pngs = list((cwd / "figs").glob("*.png"))
    assert pngs and all(p.read_bytes()[:4] == b"\x89PNG" for p in pngs)


def test_calibrated_model_file_falls_back(tmp_path: Path, cwd: Path,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    """``calibrate --out`` (the analytic fit): the output folder is replaced by a file during
    the fit; the model file goes to the current folder, exit code 1.

    Deliberate mutation that fails it: the model file written straight to ``--out`` (an
    internal error)."""
    import tomllib

    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.analysis.calibrate:calibrate", out)
    res = CliRunner().invoke(main, ["calibrate", "torsen-c", "--no-confirm", "--out",
                                    str(out / "c.toml")])
    _fell_back(res, "--out", out / "c.toml", cwd / "c.toml")
    assert "calibration" in tomllib.loads((cwd / "c.toml").read_text())


@pytest.mark.slow
def test_vehicle_results_and_figures_fall_back(tmp_path: Path, cwd: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """``vehicle`` (the open configuration for 0.02 s): the output folder is replaced by a
    file during the run; the results file and the figures go to one folder of the same name
    in the current folder, exit code 1.

    Deliberate mutations that fail it: the vehicle's writes not going through
    ``OutputFiles``; a second fallback folder for the figures (``out-1``) instead of the
    first."""
    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.analysis.vehicle_4wd:run", out)
    res = CliRunner().invoke(main, ["vehicle", "--compare", "open", "--set", "body.speed=2",
                                    "--set", "load.ramp=0.01", "--set",
                                    "run.window=[0.01,0.02]", "--t-end", "0.02", "--json",
                                    "--out", str(out)])
    _fell_back(res, "--out", out, cwd / "out")
    names = sorted(p.name for p in (cwd / "out").iterdir())
    assert names == ["comparison.png", "vehicle-4wd-open.nc", "wheel_torques.png"]
    assert not (cwd / "out-1").exists()


def test_tdr_bench_results_fall_back(tmp_path: Path, cwd: Path,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """``tdr --out DIR``: the bench evaluation is a stand-in that replaces the output folder
    by a file and then reports one finished bench run (a small dataset): its results file
    goes to a folder of the same name in the current folder, exit code 1.

    Deliberate mutations that fail it: the bench run's write not going through
    ``OutputFiles``; ``exit_if_failed`` removed from ``tdr``."""
    import types

    import xarray as xr

    import drivedyn.analysis.tdr as tdr_mod

    out = tmp_path / "out"
    out.mkdir()

    def evaluate(p, modes, *args, on_run=None, **kwargs):
        shutil.rmtree(out)
        out.write_text("the output folder was replaced by a file during the work")
        ds = xr.Dataset({"x": ("time", [0.0, 1.0])}, coords={"time": [0.0, 1.0]})
        on_run(tdr_mod.BenchRun("right", results=types.SimpleNamespace(dataset=ds),
                                size={"unknowns": 2, "coordinates": 2, "multipliers": 0,
                                      "parts": {}}))
        rows = [{"mode": 1, "name": "drive", "tdr": 1.6, "analytic": 1.6,
                 "experimental": 1.6, "error_pct": 0.0, "sim_vs_analytic_pct": 0.0}]
        return tdr_mod.TdrEvaluation(rows, [], {}, "", 125.0, 2.0)

    monkeypatch.setattr(tdr_mod, "evaluate", evaluate)
    res = CliRunner().invoke(main, ["tdr", "torsen-b", "--mode", "1", "--out", str(out)])
    _fell_back(res, "--out", out, cwd / "out")
    with xr.open_dataset(cwd / "out" / "torsen-b-bench-right.nc") as ds:
        assert list(ds["x"].values) == [0.0, 1.0]


def test_bounce_figure_falls_back(tmp_path: Path, cwd: Path,
                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """``bounce --plot`` (0.3 s of bouncing): the output folder is replaced by a file during
    the simulation; the figure goes to the current folder, the table names it, exit code 1.

    Deliberate mutation that fails it: the figure saved straight to ``--plot`` (an internal
    error)."""
    out = tmp_path / "out"
    out.mkdir()
    _sabotage(monkeypatch, "drivedyn.library.bouncing_ball:run_bounce", out)
    res = CliRunner().invoke(main, ["bounce", "--t-end", "0.3", "--plot", str(out / "b.png")])
    _fell_back(res, "--plot", out / "b.png", cwd / "b.png")
    assert (cwd / "b.png").read_bytes()[:4] == b"\x89PNG"
    assert f"figure written to {cwd / 'b.png'}" in res.output


def test_validation_report_falls_back(tmp_path: Path, cwd: Path,
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """``validate --report`` with one stand-in case (the real cases are not run): the report
    folder is replaced by a file while the case runs; ``report.md`` goes to a folder of the
    same name in the current folder, exit code 1 although the check passed.

    Deliberate mutation that fails it: the report written straight into ``--report`` (an
    internal error)."""
    import drivedyn.validation
    from drivedyn.validation.base import compare

    def case(quick: bool = False, figure_dir: str | None = None) -> list:
        return [compare("stand-in", "period", 2.0, 2.0, "s", 1e-6, source="exact")]

    monkeypatch.setattr(drivedyn.validation, "CASES", {"stand-in": case})
    rep = tmp_path / "rep"
    rep.mkdir()
    _sabotage(monkeypatch, "drivedyn.cli.validate:_run", rep)
    res = CliRunner().invoke(main, ["validate", "--case", "stand-in", "--report", str(rep)])
    _fell_back(res, "--report", rep, cwd / "rep")
    assert "1 of 1 checks passed" in (cwd / "rep" / "report.md").read_text()


# -- the fallback helper -----------------------------------------------------------------


def test_a_lost_output_names_every_path_tried_and_exits_1(
        tmp_path: Path, cwd: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """When the target, the current folder and the temporary folder all refuse the write,
    the command stops with exit code 1 and one message naming the three paths (no
    traceback).

    Deliberate mutations that fail it: the helper re-raising the ``OSError``; the message
    leaving out a path tried."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))

    def refuse(path: Path) -> None:
        raise PermissionError(13, "Permission denied", str(path))

    with pytest.raises(SystemExit) as exc:
        OutputFiles().write(refuse, tmp_path / "out" / "r.nc", "--out")
    assert exc.value.code == 1
    msg = capsys.readouterr().err
    for path in (tmp_path / "out" / "r.nc", cwd / "r.nc", tmp_path / "tmp" / "r.nc"):
        assert str(path) in msg, msg
    assert "Permission denied" in msg and "lost" in msg
