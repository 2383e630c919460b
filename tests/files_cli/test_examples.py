"""Every script in ``examples/`` runs and exits with 0; the pendulum example's figures are
checked against the exact period."""

from __future__ import annotations

import runpy
import subprocess
import sys
from pathlib import Path

import pytest

from repo import EXAMPLES

SCRIPTS = sorted(EXAMPLES.glob("*.py"))


def test_examples_exist() -> None:
    assert SCRIPTS, f"no examples found in {EXAMPLES}"


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.name for s in SCRIPTS])
def test_example_runs(script: Path, tmp_path: Path) -> None:
    """Run the script as a user would (own process, working directory outside the repo)."""
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, f"{script.name} failed:\n{proc.stdout}\n{proc.stderr}"


def test_pendulum_period_and_energy() -> None:
    """The pendulum's simulated period matches the exact elliptic-integral period."""
    ns = runpy.run_path(str(EXAMPLES / "01_pendulum.py"), run_name="example_01")
    out = ns["main"]()
    assert out["period_error"] < 1e-4
    assert out["energy_error"] < 1e-3
    assert out["period_exact"] == pytest.approx(2.17667, rel=1e-5)  # 4 sqrt(2L/3g) K(sin^2 1)


def test_beam_rollup_example() -> None:
    """The rolled-up rod follows Euler's circle arcs to Newton's tolerance (the element is
    exact for constant curvature; measured 1e-14 m) and its stress is M r / I."""
    ns = runpy.run_path(str(EXAMPLES / "06_beam_rollup.py"), run_name="example_06")
    out = ns["main"]()
    assert out["tip_error"] < 1e-12
    assert out["stress_error"] < 1e-12


def test_flexible_washer_example(drivedyn_cache) -> None:
    """The washer carries the load (equilibrium), its friction torque is mu F r_m within the
    faceting of the 36-cell mesh (measured 0.25 %), and its stress is the full FE model's
    under the same pressures (static modes; measured 2e-4, the rest is dynamics)."""
    ns = runpy.run_path(str(EXAMPLES / "07_flexible_washer.py"), run_name="example_07")
    out = ns["main"]()
    assert abs(out["force"] / 2000.0 - 1) < 1e-9
    assert abs(out["torque"] / out["torque_ref"] - 1) < 3e-3
    assert abs(out["vm"] / out["vm_full"] - 1) < 1e-3
