"""Small models of the tabulated springs, dampers and bump stops (``nonlinear_spring_damper``,
``bump_stop``) for the registry tangent test.

Each case puts several elements between different pairs of the bodies A, B, C and the
ground, so that the random velocities of the tangent test's perturbed state (seed 7) drive
some of them apart and some together: both damper branches are met. Which branch each
element is in at that state is checked by ``test_tangent_cases_meet_every_branch`` in
``tests/elements/test_nonlinear_springs.py``.
"""

from __future__ import annotations

import numpy as np

from drivedyn.model.spec import Spec
from element_cases.basic import _RB, _two_bodies

# a progressive coil spring (tension against extension: compression is negative)
SPRING = ((-0.3, -9000.0), (-0.2, -5000.0), (-0.1, -2200.0), (0.0, 0.0), (0.1, 2000.0))
REBOUND = ((0.0, 0.0), (0.5, 900.0), (1.5, 1800.0), (4.0, 2600.0))
COMPRESSION = ((0.0, 0.0), (0.3, 300.0), (1.0, 600.0), (3.0, 1000.0))
STOP = ((0.0, 0.0), (0.02, 200.0), (0.05, 1500.0), (0.08, 6000.0))

# (marker a, marker b) pairs of the cases: body to body and body to ground
PAIRS = (("mA2", "mC"), ("mB2", "mC2"), ("mA3", "mB3"), ("g1", "mC3"), ("g2", "mA4"))


def three_bodies() -> tuple[Spec, dict[str, float]]:
    """Bodies A, B (``_two_bodies``) and C, the markers of :data:`PAIRS` on them and on the
    ground, and the initial distance of each pair."""
    spec = Spec(gravity=(0.0, 0.0, -9.81))
    _two_bodies(spec)
    spec.add_rigid_body("C", 1.0, np.eye(3), position=(1.0, 0.5, -0.2), rotation=_RB)
    for name, body, p in (("mA2", "A", (-0.2, 0.1, 0.05)), ("mA3", "A", (0.1, -0.3, 0.2)),
                          ("mA4", "A", (0.0, 0.2, -0.1)), ("mB2", "B", (0.3, 0.0, -0.2)),
                          ("mB3", "B", (-0.1, 0.25, 0.1)), ("mC", "C", (0.1, 0.2, 0.3)),
                          ("mC2", "C", (-0.2, 0.1, 0.0)), ("mC3", "C", (0.0, -0.1, 0.2)),
                          ("g1", "ground", (0.5, 1.5, 0.8)), ("g2", "ground", (-0.9, 0.6, 0.4))):
        spec.add_marker(name, body, position=p)
    return spec, {f"{a}-{b}": _distance(spec, a, b) for a, b in PAIRS}


def _distance(spec: Spec, a: str, b: str) -> float:
    def point(m: str) -> np.ndarray:
        mk = spec.markers[m]
        if mk.body == "ground":
            return np.asarray(mk.position, float)
        body = spec.bodies[mk.body]
        return body.position + body.rotation @ np.asarray(mk.position, float)

    return float(np.linalg.norm(point(b) - point(a)))


def spring_tables_case() -> Spec:
    """Tabulated spring inside its table (deflections -0.25 ... 0.05 m), both damper curves
    and a preload, on every pair."""
    from drivedyn.elements.nonlinear_springs import NonlinearSpringDamper

    spec, L = three_bodies()
    for i, (a, b) in enumerate(PAIRS):
        x = -0.25 + 0.07 * i  # deflection at the initial configuration
        spec.add(NonlinearSpringDamper(f"s{i}", a, b, spring_curve=SPRING,
                                       free_length=L[f"{a}-{b}"] - x,
                                       damper_curve_rebound=REBOUND,
                                       damper_curve_compression=COMPRESSION,
                                       preload=25.0 * (i - 2)))
    return spec


def spring_extrapolation_case() -> Spec:
    """Beyond both ends of the tables: deflections below -0.3 m and above 0.1 m, speeds
    beyond the damper tables (scaled down so that the random speeds leave them); a linear
    spring; dampers with one branch only, moving the other way; a damper without a spring;
    the free length left to the initial distance."""
    from drivedyn.elements.nonlinear_springs import NonlinearSpringDamper

    small = tuple((v * 0.1, f) for v, f in REBOUND)
    spec, L = three_bodies()
    (a0, b0), (a1, b1), (a2, b2), (a3, b3), (a4, b4) = PAIRS
    spec.add(NonlinearSpringDamper("below", a0, b0, spring_curve=SPRING,
                                   free_length=L[f"{a0}-{b0}"] + 0.4,
                                   damper_curve_rebound=small, damper_curve_compression=small))
    spec.add(NonlinearSpringDamper("above", a1, b1, spring_curve=SPRING,
                                   free_length=L[f"{a1}-{b1}"] - 0.25,
                                   damper_curve_rebound=small, damper_curve_compression=small))
    # the branches these two have no curve for (no damping force there)
    spec.add(NonlinearSpringDamper("linear", a2, b2, stiffness=3000.0,
                                   free_length=L[f"{a2}-{b2}"] + 0.1,
                                   damper_curve_rebound=REBOUND))
    spec.add(NonlinearSpringDamper("compression_only", a3, b3, stiffness=500.0,
                                   damper_curve_compression=COMPRESSION))
    spec.add(NonlinearSpringDamper("damper_only", a4, b4, damper_curve_rebound=small,
                                   damper_curve_compression=COMPRESSION))
    return spec


def bump_stop_closed_case() -> Spec:
    """Stops in contact: inside their onset ramp and beyond it, beyond the last point of the
    table, with damping; compression and extension stops."""
    from drivedyn.elements.nonlinear_springs import BumpStop

    spec, _ = three_bodies()
    (a0, b0), (a1, b1), (a2, b2), (a3, b3), (a4, b4) = PAIRS
    spec.add(BumpStop("ramp", a0, b0, STOP, gap=-0.03, damping=300.0, transition=0.05))
    spec.add(BumpStop("beyond_ramp", a1, b1, STOP, gap=-0.06, damping=200.0,
                      transition=0.03))
    spec.add(BumpStop("beyond_table", a2, b2, STOP, gap=-0.12, damping=100.0,
                      transition=0.01))
    spec.add(BumpStop("no_ramp", a3, b3, STOP, gap=-0.04))
    spec.add(BumpStop("rebound_stop", a4, b4, STOP, gap=-0.05, damping=200.0,
                      transition=0.04, side="extension"))
    return spec


def bump_stop_open_case() -> Spec:
    """Stops out of contact (exactly no force), and one in contact whose damping would pull
    (the force held at zero)."""
    from drivedyn.elements.nonlinear_springs import BumpStop

    spec, _ = three_bodies()
    (a0, b0), (a1, b1), _, (a3, b3), (a4, b4) = PAIRS
    spec.add(BumpStop("open", a0, b0, STOP, gap=0.1, damping=300.0, transition=0.05))
    spec.add(BumpStop("open_rebound", a1, b1, STOP, gap=0.08, side="extension"))
    spec.add(BumpStop("held", a3, b3, STOP, gap=-0.03, damping=1.0e5, transition=0.01))
    spec.add(BumpStop("held_rebound", a4, b4, STOP, gap=-0.03, damping=1.0e5,
                      transition=0.01, side="extension"))
    return spec


SPRING_CASES = [spring_tables_case, spring_extrapolation_case]
STOP_CASES = [bump_stop_closed_case, bump_stop_open_case]
