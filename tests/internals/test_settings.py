"""Process-wide settings (drivedyn.settings) and their command-line options: the values
reach what reads them, the defaults are the documented ones, and bad values are refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from drivedyn import settings


@pytest.fixture
def restored():
    """The settings in force before the test, restored after it."""
    before = settings.current()
    yield
    settings._current = before


def test_defaults_are_the_cpu_count_and_the_cache_variable(monkeypatch, restored) -> None:
    """No setting: one compile worker per CPU; the cache folder from $DRIVEDYN_CACHE, else
    ~/.cache/drivedyn. Fails if a default is hard-coded or the variable ignored."""
    import os

    settings._current = settings.ProcessSettings()
    assert settings.compile_workers() == (os.cpu_count() or 1)
    monkeypatch.setenv("DRIVEDYN_CACHE", "/tmp/somewhere")
    assert settings.cache_dir() == Path("/tmp/somewhere")
    monkeypatch.delenv("DRIVEDYN_CACHE")
    assert settings.cache_dir() == Path.home() / ".cache" / "drivedyn"


def test_configure_sets_only_what_it_is_given(tmp_path, restored) -> None:
    """A later configure() call keeps the values it does not name; the cache folder setting
    wins over the environment variable; negative workers are refused naming the value."""
    settings.configure(compile_workers=0)
    settings.configure(cache_dir=tmp_path)
    assert settings.compile_workers() == 0 and settings.cache_dir() == tmp_path
    with pytest.raises(ValueError, match="-1"):
        settings.configure(compile_workers=-1)
    assert settings.compile_workers() == 0


def test_the_reduction_cache_follows_the_setting(tmp_path, restored) -> None:
    """The Craig-Bampton cache (drivedyn.fe.reduction) is kept in the configured folder."""
    from drivedyn.fe import reduction

    settings.configure(cache_dir=tmp_path / "c")
    assert reduction._cache_dir() == tmp_path / "c"


def test_command_line_options_configure_the_process(tmp_path, restored) -> None:
    """``drivedyn --compile-workers N --cache-dir DIR COMMAND`` sets both for the command;
    a negative N is a usage error (exit 2)."""
    from click.testing import CliRunner

    from drivedyn.cli import main

    seen = {}

    @main.command("probe-settings")
    def probe() -> None:
        seen["workers"] = settings.compile_workers()
        seen["cache"] = settings.cache_dir()
        seen["progress"] = settings.current().compile_progress

    try:
        runner = CliRunner()
        res = runner.invoke(main, ["--compile-workers", "3", "--cache-dir", str(tmp_path),
                                   "probe-settings"])
        assert res.exit_code == 0, res.output
        assert seen["workers"] == 3 and seen["cache"] == tmp_path
        assert seen["progress"] is not None  # the CLI prints a first run's compilation
        res = runner.invoke(main, ["--compile-workers", "-2", "probe-settings"])
        assert res.exit_code == 2
    finally:
        main.commands.pop("probe-settings", None)


def test_the_cli_prints_compile_progress_on_stderr(capsys) -> None:
    """What a first run shows: the number of kernels, then each one as it is compiled."""
    from drivedyn.cli import _compile_progress

    _compile_progress(0, 3, "")
    _compile_progress(1, 3, "gear_kernel")
    err = capsys.readouterr().err.splitlines()
    assert "compiling 3 numba kernels" in err[0] and "gear_kernel (1 of 3)" in err[1]
