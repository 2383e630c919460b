"""The dashboard of a RWD run (``drivedyn plot``; vocabulary:
:mod:`drivedyn.library.dashboards`): the rear wheels' drive torques (reaction torques of
the outboard universal joints on the wheels, global components: the y component is the
torque about the spin axis to within the wheels' camber and toe), tyre slips and loads,
wheel speeds and the vehicle speed, the analysis window ``run.window`` shaded."""

from __future__ import annotations

from typing import Any

from drivedyn.library.dashboards import Curve, Dashboard, Page, Panel, Term, Window
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS

LABELS = {"fl": "front left", "fr": "front right", "rl": "rear left", "rr": "rear right"}


def vehicle_dashboard(p: Any) -> Dashboard:
    """The dashboard of a run of the vehicle with validated parameters ``p``."""
    window = (Window(*p.run.window, "analysis window"),)
    mu = {w: getattr(p.road.mu, w) for w in WHEELS}
    torques = Panel("rear wheel drive torques", "torque", "N m",
                    tuple(Curve(f"{LABELS[w]} (road {mu[w]:g})",
                                (Term(f"halfshaft_{w}_outer.torque_y"),)) for w in ("rl", "rr")),
                    windows=window)
    slips = Panel("tyre longitudinal slip", "slip", "1",
                  tuple(Curve(LABELS[w], (Term(f"tyre_{w}.kappa"),)) for w in WHEELS),
                  display="%")
    loads = Panel("tyre vertical loads", "force", "N",
                  tuple(Curve(LABELS[w], (Term(f"tyre_{w}.fz"),)) for w in WHEELS))
    fx = Panel("tyre longitudinal forces", "force", "N",
               tuple(Curve(LABELS[w], (Term(f"tyre_{w}.fx"),)) for w in WHEELS))
    speed = Panel("vehicle speed", "speed", "m/s",
                  (Curve("rear left wheel centre, forward", (Term("wheel_rl.velocity", 0),),
                         style="k"),))
    page = Page("rear axle torque transfer", (torques, slips, loads, fx, speed))
    return Dashboard(name="dashboard_vehicle_rwd",
                     title=f"RWD vehicle: rear {p.differentials.rear}", pages=(page,))
