"""Validation figures that do not depend on the machine's round-off.

The cases whose results once moved with the LU's round-off (the TORSEN Type B in vehicle
configuration, the 4WD vehicle with three TORSENs, both benches) and the RWD vehicle's
(a flexible frame on bushings: 800 unknowns, sparse LU) run in two processes under
two OpenBLAS settings: the library's own kernel choice with two threads, and the Sandy
Bridge kernels with one thread (``OPENBLAS_CORETYPE``, ``OPENBLAS_NUM_THREADS``: other
blockings and summation orders inside ``dgetrf``). Every figure must agree within 0.1 %
(:func:`allowed`).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

CASES = ("torsen_b_vehicle", "vehicle_4wd_split_mu", "torsen_b_bench", "torsen_c_tdr",
         "rwd_static_loads", "rwd_split_mu", "rwd_steady_cornering")
SETTINGS = (
    {"OPENBLAS_NUM_THREADS": "2"},
    {"OPENBLAS_CORETYPE": "SANDYBRIDGE", "OPENBLAS_NUM_THREADS": "1"},
)


def _validate(env_extra: dict[str, str]) -> list[dict]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("OPENBLAS_")}
    env.update(env_extra)
    # --jobs 1: the cases in the process the settings are given to (a case process of
    # ``validate`` takes one BLAS thread, whatever OPENBLAS_NUM_THREADS says)
    cmd = [sys.executable, "-m", "drivedyn.cli", "validate", "--quick", "--json", "--jobs", "1"]
    for c in CASES:
        cmd += ["--case", c]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=1800)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout)


def allowed(row: dict) -> float:
    """How far a figure may move between the two settings: 0.1 % of its magnitude (TDRs,
    ratios, splits) or of the limit of a bound (stored as the reference, tolerance 0); a
    balance by a tenth of its tolerance, whether compared with 0 (its tolerance) or checked
    against a limit (``at_most``: its limit). Such a balance is a small remainder (what
    Newton's tolerance leaves, or a window-mean inertia torque of the mesh-stiffness ripple,
    whose phase at the window's ends round-off moves): its own relative change means nothing,
    its distance from its tolerance does (the issue asks "balances within their
    tolerances"). Measured: the Type B bench's right-side balance 2.46e-6 and 2.67e-6 of the
    applied torque (2 % of its 1e-5); the 4WD's front TORSEN balance 1.61e-6 and 1.73e-6
    (limit 5e-5; Newton's tolerance 1e-4 in vehicle-4wd.toml)."""
    if row["reference"] == 0:
        return 0.1 * row["tolerance"]
    if row["tolerance"] == 0:
        if "balance" in row["quantity"]:
            return 0.1 * abs(row["reference"])
        return 1e-3 * max(abs(row["simulated"]), abs(row["reference"]))
    return 1e-3 * abs(row["simulated"])


@pytest.mark.slow
def test_validation_figures_under_two_blas_settings() -> None:
    """Fails if a run is sensitive to round-off: with ``pockets.oil_film = false`` in
    torsen-b.toml (the element gears whirl in their pockets) the Type B vehicle's forward
    mode 4 TDR came out 1.6791 and 1.6745 under the two settings (0.28 %). Measured with the
    film: every TDR within 2.5e-5, the 4WD traction ratio within 1.8e-4."""
    a, b = (_validate(s) for s in SETTINGS)
    assert [(r["case"], r["quantity"]) for r in a] == [(r["case"], r["quantity"]) for r in b]
    worse = [(x["case"], x["quantity"], x["simulated"], y["simulated"])
             for x, y in zip(a, b, strict=True)
             if abs(x["simulated"] - y["simulated"]) > allowed(x)]
    assert not worse, worse
