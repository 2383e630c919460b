"""The dashboard of a RWD run (``drivedyn plot``; vocabulary:
:mod:`drivedyn.library.dashboards`): one figure of nine panels.

* rear wheel drive torques [N m]: the reaction torques of the outboard universal joints on
  the wheels, global y component (the torque about the spin axis to within the wheels'
  camber and toe), labelled with each wheel's road friction factor, the analysis window
  ``run.window`` shaded with the window means (the seeds' figure: the torque transfer of
  the TORSEN differential when the vehicle pulls away on a slippery surface);
* wheel speeds [rpm] (``tyre_*.spin``), tyre longitudinal slips [%], tyre longitudinal
  forces ``fx`` and vertical loads ``fz`` [N];
* the vehicle: its forward speed, yaw rate [deg/s] and path (y against x) [m], taken as the
  mean of the body's carriers (``frame.body.*``, one at each body mount on each rail);
* frame stresses [Pa]: the largest von Mises stress over the rails' and over the cross
  members' beam elements at each output time (``frame.*.von_mises``: per element, the
  largest of ``sqrt(sigma^2 + 3 tau^2)`` on the outer fibre of its box section at its
  Gauss point, :func:`drivedyn.elements.beams.section.outer_fibre_stresses`).
"""

from __future__ import annotations

from typing import Any

from drivedyn.library.dashboards import (
    Abscissa,
    Curve,
    Dashboard,
    Page,
    Panel,
    Term,
    Window,
)
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS

LABELS = {"fl": "front left", "fr": "front right", "rl": "rear left", "rr": "rear right"}
#: the frame's prefix in the built model (its beams ``frame.left.e0``..., body carriers
#: ``frame.body.left0``...)
FRAME = "frame"
#: panel titles, in the order of the figure
TITLES = ("rear wheel drive torques", "wheel speeds", "tyre longitudinal slip",
          "tyre longitudinal forces", "tyre vertical loads", "vehicle speed", "yaw rate",
          "path", "frame stresses (peak von Mises)")


def _body(p: Any, variable: str, component: int) -> Term:
    """The mean of ``variable[component]`` over the body's carriers."""
    n = max(1, 2 * len(p.body.mounts))
    return Term(f"{FRAME}.body.*.{variable}", component, coefficient=1.0 / n)


def _per_wheel(title: str, quantity: str, unit: str, output: str,
               display: str | None = None) -> Panel:
    return Panel(title, quantity, unit,
                 tuple(Curve(LABELS[w], (Term(f"tyre_{w}.{output}"),)) for w in WHEELS),
                 display=display)


def vehicle_dashboard(p: Any) -> Dashboard:
    """The dashboard of a run of the vehicle with validated parameters ``p``."""
    window = (Window(*p.run.window, "analysis window"),)
    mu = {w: getattr(p.road.mu, w) for w in WHEELS}
    t_torques, t_spin, t_slip, t_fx, t_fz, t_speed, t_yaw, t_path, t_stress = TITLES
    torques = Panel(t_torques, "torque", "N m",
                    tuple(Curve(f"{LABELS[w]} (road {mu[w]:g})",
                                (Term(f"halfshaft_{w}_outer.torque_y"),)) for w in ("rl", "rr")),
                    windows=window)
    speed = Panel(t_speed, "speed", "m/s",
                  (Curve("body, forward", (_body(p, "velocity", 0),), style="k"),))
    yaw = Panel(t_yaw, "yaw rate", "rad/s",
                (Curve("body, about z", (_body(p, "angular_velocity", 2),), style="k"),),
                display="deg/s")
    path = Panel(t_path, "y", "m", (Curve("body", (_body(p, "position", 1),), style="k"),),
                 abscissa=Abscissa("x", "m", Curve("body", (_body(p, "position", 0),))))
    stress = Panel(t_stress, "stress", "Pa",
                   (Curve("rails", (Term(f"{FRAME}.[lr]*.von_mises", reduce="max"),)),
                    Curve("cross members", (Term(f"{FRAME}.cross*.von_mises", reduce="max"),))),
                   note="largest over the elements at each time; outer fibre of the box "
                        "section, sqrt(sigma^2 + 3 tau^2)")
    page = Page("split-mu launch",
                (torques, _per_wheel(t_spin, "speed", "rad/s", "spin", "rpm"),
                 _per_wheel(t_slip, "slip", "1", "kappa", "%"),
                 _per_wheel(t_fx, "force", "N", "fx"), _per_wheel(t_fz, "force", "N", "fz"),
                 speed, yaw, path, stress))
    return Dashboard(name="dashboard_vehicle_rwd",
                     title=f"RWD vehicle: rear {p.differentials.rear}", pages=(page,))
