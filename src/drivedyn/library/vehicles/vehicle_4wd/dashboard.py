"""The dashboard of a four-wheel-drive run (``drivedyn plot``; vocabulary:
:mod:`drivedyn.library.dashboards`).

Two pages:

* wheels and torque split: the drive torque of each wheel (minus its half-shaft spring's
  torque, forward positive, labelled with the road's friction factor), the tyres'
  longitudinal slips [%], the wheel speeds [rpm] and the vehicle speed, the torque splits
  (front share of the four wheel torques, left share of each axle) and the torque ratios
  (larger / smaller) of the three differentials: central (propeller shafts), front and rear
  axle; the analysis window ``run.window`` shaded;
* driveline and tyres: the propeller-shaft torques, the tyres' longitudinal and vertical
  forces, and the dissipated power of the tyres, of the central differential and of each
  axle drive (elements named ``central_*``, ``front_*``, ``rear_*``), of the shafts and in
  total.
"""

from __future__ import annotations

from typing import Any

from drivedyn.library.dashboards import Curve, Dashboard, Page, Panel, Term, Window
from drivedyn.library.vehicles.vehicle_4wd.schema import WHEELS

LABELS = {"fl": "front left", "fr": "front right", "rl": "rear left", "rr": "rear right"}


def _drive(w: str) -> Term:
    """Drive torque [N m] of wheel ``w``: minus its half-shaft spring's torque."""
    return Term(f"halfshaft_{w}.torque", coefficient=-1.0)


def _wheels(p: Any) -> Page:
    window = (Window(*p.run.window, "analysis window"),)
    mu = {w: getattr(p.road.mu, w) for w in WHEELS}
    torques = Panel("wheel drive torques", "torque", "N m",
                    tuple(Curve(f"{LABELS[w]} (road {mu[w]:g})", (_drive(w),)) for w in WHEELS),
                    windows=window)
    slips = Panel("tyre longitudinal slip", "slip", "1",
                  tuple(Curve(LABELS[w], (Term(f"tyre_{w}.kappa"),)) for w in WHEELS),
                  display="%")
    spins = Panel("wheel speeds", "speed", "rad/s",
                  tuple(Curve(LABELS[w], (Term(f"wheel_{w}.angular_velocity", 1),))
                        for w in WHEELS), display="rpm")
    speed = Panel("vehicle speed", "speed", "m/s",
                  (Curve("car body, forward", (Term("body.velocity", 0),), style="k"),))
    front = (_drive("fl"), _drive("fr"))
    rear = (_drive("rl"), _drive("rr"))
    splits = Panel("torque splits", "share", "1",
                   (Curve("front / total", front, over=front + rear),
                    Curve("left / front axle", (_drive("fl"),), over=front),
                    Curve("left / rear axle", (_drive("rl"),), over=rear)),
                   display="%", windows=window)
    ratios = Panel("torque ratios of the differentials (larger / smaller)", "ratio", "1",
                   (Curve("central (propeller shafts)", (Term("prop_front_spring.torque"),),
                          over=(Term("prop_rear_spring.torque"),), ratio="larger_over_smaller"),
                    Curve("front axle", (_drive("fl"),), over=(_drive("fr"),),
                          ratio="larger_over_smaller"),
                    Curve("rear axle", (_drive("rl"),), over=(_drive("rr"),),
                          ratio="larger_over_smaller")),
                   windows=window)
    return Page("wheels and torque split", (torques, slips, spins, speed, splits, ratios))


def _driveline() -> Page:
    props = Panel("propeller shaft torques", "torque", "N m",
                  tuple(Curve(f"{axle} propeller shaft",
                              (Term(f"prop_{axle}_spring.torque", coefficient=-1.0),))
                        for axle in ("front", "rear")))
    fx = Panel("tyre longitudinal forces", "force", "N",
               tuple(Curve(LABELS[w], (Term(f"tyre_{w}.fx"),)) for w in WHEELS))
    fz = Panel("tyre vertical loads", "force", "N",
               tuple(Curve(LABELS[w], (Term(f"tyre_{w}.fz"),)) for w in WHEELS))
    losses = Panel("dissipated power", "power", "W",
                   (Curve("tyres", (Term("tyre_*.dissipated_power"),)),
                    *(Curve(label, (Term(f"{pos}_*.dissipated_power"),))
                      for pos, label in (("central", "central differential"),
                                         ("front", "front axle (differential, bevel)"),
                                         ("rear", "rear axle (differential, bevel)"))),
                    Curve("shafts", (Term("halfshaft_*.dissipated_power"),
                                     Term("prop_*.dissipated_power"))),
                    Curve("total", (Term("*.dissipated_power"),), style="k")))
    return Page("driveline and tyres", (props, fx, fz, losses))


def vehicle_dashboard(p: Any) -> Dashboard:
    """The dashboard of a run of the vehicle with validated parameters ``p``."""
    d = p.differentials
    return Dashboard(name="dashboard_vehicle_4wd",
                     title=f"4WD vehicle: central {d.central}, front {d.front}, rear {d.rear}",
                     pages=(_wheels(p), _driveline()))
