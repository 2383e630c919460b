"""Rack-and-pinion steering: the rack on a prismatic joint, its travel prescribed by a
:class:`~drivedyn.elements.TravelDriver` from the steering function.

The pinion is not a body: the function gives the rack travel, or the pinion angle that the
builder turns into travel by the rack ratio (``travel = ratio * angle``). Positive travel
moves the rack along the file's ``axis`` (the vehicle's left by default); with tie rods
behind the wheel centres, as in the shipped data, that steers both wheels to the right.

The travel limit is checked when the model is built: every time function of
:mod:`drivedyn.timefunctions` is a known profile, constant after its last breakpoint, so its
largest magnitude is found from its breakpoints (a ramp, smooth step or table is monotone
between them) and, for a sum of several terms, from 64 samples between consecutive
breakpoints (a sum of monotone pieces may peak between them: the sampled peak is then a
lower bound within the curvature of 1/64 of an interval).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from drivedyn.elements import Prismatic, TravelDriver
from drivedyn.elements.framework.visuals import cylinder
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions.geometry import (
    Mount,
    chassis_marker,
    frame,
    marker_at,
    unit,
)
from drivedyn.library.vehicles.suspensions.schema import SteeringFile
from drivedyn.model.spec import Spec
from drivedyn.timefunctions import Sum, TimeFunction, as_time_function

#: samples between breakpoints of a sum of several terms
SUM_SAMPLES = 64


@dataclass
class Rack:
    """Names of a built rack-and-pinion steering.

    Attributes:
        body: the rack body.
        left, right: markers on the rack at the tie rods' inner joints (pass them as
            ``steer`` to :func:`~drivedyn.library.vehicles.suspensions.double_wishbone.
            add_double_wishbone`).
        joint: the prismatic joint of the rack.
        driver: the travel driver (its output ``force`` is the rack force [N]).
        travel: the rack travel [m] as a function of time.
    """

    body: str
    left: str
    right: str
    joint: str
    driver: str
    travel: TimeFunction

    def marker(self, side: str) -> str:
        """The tie-rod joint marker of ``side``."""
        return self.left if side == "left" else self.right


def peak_magnitude(fn: TimeFunction) -> tuple[float, float]:
    """Largest ``|f(t)|`` over ``t >= 0`` and a time where it occurs [s] (see the module
    docstring for how it is found)."""
    bps = sorted({0.0, *(b for b in fn.breakpoints() if b > 0.0)})
    times = list(bps)
    if isinstance(fn, Sum) and len(fn.terms()) > 1:
        for a, b in itertools.pairwise(bps):
            times += list(np.linspace(a, b, SUM_SAMPLES + 2)[1:-1])
    times.append(bps[-1] + 1.0)  # constant beyond the last breakpoint
    values = np.abs(np.array([fn(t) for t in times], dtype=float))
    i = int(np.argmax(values))
    return float(values[i]), float(times[i])


def add_rack_steering(sp: Spec, prefix: str, p: SteeringFile, mount: Mount, function: Any,
                      quantity: Literal["travel", "pinion_angle"] = "pinion_angle") -> Rack:
    """Build the rack of ``p`` into ``sp``, driven by ``function``.

    Args:
        sp: the model being built; the chassis is already in it.
        prefix: names of the rack's body, markers and elements start with it.
        p: the steering.
        mount: ``mount(name, point)``: a marker on the chassis at a global point (see
            :func:`~drivedyn.library.vehicles.suspensions.double_wishbone.
            add_double_wishbone`).
        function: the steering input as a time function (a number, a
            :class:`~drivedyn.timefunctions.TimeFunction` or its dict): the pinion angle
            [rad] or the rack travel [m] from the centre, by ``quantity``.
        quantity: ``"pinion_angle"`` or ``"travel"``.

    Returns:
        the :class:`Rack`.

    Raises:
        ModelError: a function whose travel exceeds ``travel_limit`` somewhere (naming the
            value, the time and the limit), an unknown quantity, an unreadable function.
    """
    if quantity not in ("travel", "pinion_angle"):
        raise ModelError(f"steering {prefix!r}: quantity must be 'travel' or 'pinion_angle', "
                         f"got {quantity!r}")
    try:
        fn = as_time_function(function)
    except (TypeError, ValueError) as exc:
        raise ModelError(f"steering {prefix!r}.function: {exc}") from None
    travel = p.ratio * fn if quantity == "pinion_angle" else fn
    peak, t_peak = peak_magnitude(travel)
    if peak > p.travel_limit * (1.0 + 1e-12):
        given = (f"pinion angle {peak / p.ratio:.6g} rad (rack travel {peak:.6g} m)"
                 if quantity == "pinion_angle" else f"rack travel {peak:.6g} m")
        raise ModelError(f"steering {prefix!r}.function: {given} at t = {t_peak:g} s exceeds "
                         f"travel_limit = {p.travel_limit:g} m")
    left, right = p.point("left"), p.point("right")
    axis = unit(np.asarray(p.axis, dtype=float), f"steering {prefix!r}.axis")
    R = frame(np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 0.0, 1.0]),
              axis)
    centre = (left + right) / 2.0 if p.rack.com is None else (
        np.asarray(p.location) + np.asarray(p.rack.com))
    body = sp.add_rigid_body(f"{prefix}_rack", p.rack.mass, p.rack.inertia, position=centre)
    guide = chassis_marker(sp, mount, f"{prefix}_rack_guide", centre, R)
    slide = marker_at(sp, f"{prefix}_rack_slide", body, centre, R)
    joint = sp.add(Prismatic(f"{prefix}_rack_slide", guide, slide)).name
    driver = sp.add(TravelDriver(f"{prefix}_rack_drive", joint, travel)).name
    m_left = marker_at(sp, f"{prefix}_rack_left", body, left)
    m_right = marker_at(sp, f"{prefix}_rack_right", body, right)
    sp.add_visual(cylinder(slide, 0.02, float(np.linalg.norm(left - right)), role="part",
                           label=body))
    return Rack(body, m_left, m_right, joint, driver, travel)
