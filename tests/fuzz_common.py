"""What the fuzzing tests share (``tests/files_cli/test_fuzz*.py``): the two hypothesis
profiles, a small TOML writer, the command line run in-process and the checks every outcome
must pass (no traceback, no internal error; exit 1 with a reason; exit 2 naming the input).

Profiles: :data:`SHORT` runs in CI (derandomized, a few cheap examples per test);
:data:`LONG` runs under the ``fuzz_long`` marker (``pytest -m fuzz_long``, random examples).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Any

from click.testing import CliRunner
from hypothesis import HealthCheck, settings

from drivedyn.cli import main

_HEALTH = [HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
           HealthCheck.data_too_large, HealthCheck.filter_too_much]
SHORT = settings(max_examples=12, deadline=None, derandomize=True, database=None,
                 suppress_health_check=_HEALTH)
LONG = settings(max_examples=300, deadline=None, suppress_health_check=_HEALTH)


def short(n: int) -> settings:
    """The CI profile with ``n`` examples (for tests whose examples simulate)."""
    return settings(SHORT, max_examples=n)


def long(n: int) -> settings:
    """The long profile with ``n`` examples."""
    return settings(LONG, max_examples=n)


# -- a small TOML writer (values: str, bool, int, float, lists, inline tables) ------------------

def toml_value(v: Any) -> str:
    """``v`` as a TOML value (``nan``, ``inf`` and ``-inf`` for the special floats)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v == math.inf else
                                             "-inf" if v == -math.inf else repr(v))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(v)


def to_toml(model: dict) -> str:
    """A model dict (tables of values, or lists of tables) as TOML text."""
    lines: list[str] = []
    for key, val in model.items():
        if isinstance(val, dict):
            lines.append(f"[{key}]")
            lines += [f"{k} = {toml_value(x)}" for k, x in val.items()]
        else:
            for item in val:
                lines.append(f"[[{key}]]")
                lines += [f"{k} = {toml_value(x)}" for k, x in item.items()]
        lines.append("")
    return "\n".join(lines)


# -- the command line and the checks of its outcome -----------------------------------------

@dataclass
class Outcome:
    """Exit code and text (standard output and error) of one command."""

    args: list[str]
    exit_code: int
    text: str

    def show(self) -> str:
        return f"drivedyn {' '.join(self.args)}\nexit {self.exit_code}\n{self.text}"


def cli(args: list[str]) -> Outcome:
    """``drivedyn ARGS`` in-process. An exception escaping the command group (anything but
    the exits of click) is itself a hole: it fails the test with its traceback.

    With ``$DRIVEDYN_FUZZ_LOG`` set, each command, its exit code and its last line are
    appended to that file (one JSON object a line): what a fuzzing session tried."""
    res = CliRunner().invoke(main, args)
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        raise AssertionError(f"drivedyn {' '.join(args)} raised {res.exception!r}") \
            from res.exception
    log = os.environ.get("DRIVEDYN_FUZZ_LOG")
    if log:
        last = (res.output.strip().splitlines() or [""])[-1]
        with open(log, "a") as f:
            f.write(json.dumps({"args": args, "exit": res.exit_code, "last": last}) + "\n")
    return Outcome(list(args), res.exit_code, res.output)


def assert_no_crash(out: Outcome) -> None:
    """Never a traceback, never an internal error, only the documented exit codes."""
    assert "Traceback" not in out.text and "internal error" not in out.text, out.show()
    assert out.exit_code in (0, 1, 2), out.show()


#: what a failure prints (``run``: ``FAILED: <reason>``; ``vehicle``: ``FAIL <check>``;
#: ``tdr``: ``... failed: <reason>``)
FAILURE_WORDS = ("FAILED", "FAIL ", "failed", "stopped at")


def assert_clean(out: Outcome) -> None:
    """A run that either succeeded, or failed with a reason (exit 1), or refused its input
    with ``error: ...`` (exit 2)."""
    assert_no_crash(out)
    if out.exit_code == 1:
        assert any(w in out.text for w in FAILURE_WORDS), out.show()
    if out.exit_code == 2:
        assert "error: " in out.text, out.show()


def assert_refused(out: Outcome, *needles: str) -> None:
    """Exit 2, ``error: ...`` naming every one of ``needles`` (the file, the key...)."""
    assert_no_crash(out)
    assert out.exit_code == 2, out.show()
    assert "error: " in out.text, out.show()
    for n in needles:
        assert n in out.text, f"the message does not name {n!r}:\n{out.show()}"
