"""A kinematics-and-compliance rig for one corner, and the corner's design-position numbers.

The rig holds the chassis fixed (the ground) and moves the wheel centre vertically: a wheel
pad on a vertical prismatic joint driven by a :class:`~drivedyn.elements.TravelDriver`
(``actuator``, its ``force`` output the vertical wheel force [N]), carrying two cross slides
(x, then y) and a ball joint at the wheel centre, so that the wheel centre's height is
imposed while it moves freely along and across and the upright turns freely. Static
equilibria at the driver's values (:func:`~drivedyn.solver.solve_static`) give the
quasi-static kinematics and the wheel rate; without gravity the pad's force is the wheel
load that the suspension carries at that travel.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import brentq

from drivedyn.elements import Prismatic, Spherical, TravelDriver
from drivedyn.elements.framework.curves import curve_value, pack_curves
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions.corner import AnyCorner, AnySuspension, add_corner
from drivedyn.model import Model, Spec, compile_model
from drivedyn.solver import element_outputs, solve_static
from drivedyn.timefunctions import Table

#: rig bodies' mass [kg] and inertia [kg m^2] (only their constraints matter in statics)
RIG_MASS, RIG_INERTIA = 1.0, (1e-3, 1e-3, 1e-3)
#: wheel travel [m] of the central differences of :func:`design_point`
STEP = 1e-4


def corner_rig(p: AnySuspension, travel: Any, side: str = "left",
               rigid_bushings: bool = True) -> tuple[Model, AnyCorner]:
    """A corner (``prefix`` ``"corner"``) of ``p`` (either type) on the ground with the wheel
    pad rig, the pad's vertical travel [m] from the design position given by the time
    function ``travel``; the tie rod's inner joint on the chassis (the rack held)."""
    sp = Spec()

    def mount(name: str, point: np.ndarray) -> str:
        return sp.add_marker(name, "ground", position=point)

    c = add_corner(sp, "corner", side, p, mount, rigid_bushings=rigid_bushings)
    w = c.wheel_center
    axes = {"z": (0.0, 0.0, 1.0), "x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0)}
    carrier = "ground"
    for body, ax in (("pad", "z"), ("slide_x", "x"), ("slide_y", "y")):
        sp.add_rigid_body(body, RIG_MASS, RIG_INERTIA, position=w)
        guide = sp.add_marker(f"{body}_guide", carrier,
                              position=w if carrier == "ground" else (0.0, 0.0, 0.0),
                              axis=axes[ax])
        sp.add(Prismatic(f"{body}_rail", guide, sp.add_marker(f"{body}_slider", body,
                                                              axis=axes[ax])))
        carrier = body
    sp.add(TravelDriver("actuator", "pad_rail", travel))
    sp.add_marker("rig_ball", "slide_y")
    sp.add(Spherical("wheel_ball", "rig_ball", c.hub))
    return compile_model(sp), c


@dataclass
class DesignPoint:
    """A corner in its design position (rigid pivots, no gravity).

    Attributes:
        wheel_load: vertical force [N] on the wheel centre that holds the corner there.
        spring_force: the spring's tension [N] (negative: compressed).
        spring_length: [m].
        installation_ratio: ``-dL_spring / dz_wheel`` (1).
        wheel_rate: ``dF / dz_wheel`` [N/m] at the wheel centre.
    """

    wheel_load: float
    spring_force: float
    spring_length: float
    installation_ratio: float
    wheel_rate: float


def design_point(p: AnySuspension) -> DesignPoint:
    """The :class:`DesignPoint` of the left corner of ``p`` (central differences over
    +-:data:`STEP` of wheel travel)."""
    model, c = corner_rig(p, Table((0.0, 1.0, 2.0), (0.0, STEP, -STEP)))
    st = model.initial_state()
    out = []
    for t in (0.0, 1.0, 2.0):
        st = solve_static(model, st, t=t)
        out.append(element_outputs(model, st))
    f = [o["actuator"]["force"] for o in out]
    length = [o[c.spring]["length"] for o in out]
    return DesignPoint(f[0], out[0][c.spring]["force"], length[0],
                       -(length[1] - length[2]) / (2.0 * STEP), (f[1] - f[2]) / (2.0 * STEP))


def free_length_for_load(p: AnySuspension, wheel_load: float) -> float:
    """The spring's free length [m] with which the corner carries ``wheel_load`` [N] at its
    design position (its ride height): the spring pushes ``wheel_load / IR`` there.

    Raises:
        ModelError: a load that is not positive.
    """
    if not wheel_load > 0.0:
        raise ModelError(f"free_length_for_load: wheel_load must be > 0 N, got {wheel_load!r}")
    dp = design_point(p)
    tension = -wheel_load / dp.installation_ratio
    if p.spring.curve is None:
        assert p.spring.rate is not None
        x = tension / p.spring.rate
    else:
        xs, ys = zip(*p.spring.curve, strict=True)
        X, Y, D, start = pack_curves([(xs, ys)])

        def g(q: float) -> float:
            return float(curve_value(X, Y, D, start, 0, q)[0]) - tension

        lo, hi = -1.0, 1.0  # the curve goes on linearly beyond its ends
        while g(lo) > 0.0:
            lo *= 2.0
        while g(hi) < 0.0:
            hi *= 2.0
        x = brentq(g, lo, hi, xtol=1e-15)
    return dp.spring_length - x
