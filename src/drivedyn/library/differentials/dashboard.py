"""The dashboard of any differential's run (``drivedyn plot``), declared from its
:class:`~drivedyn.library.differentials.base.Differential` record and the scenario of its
parameters (:mod:`drivedyn.library.dashboards` says how it is drawn).

Two or three pages:

* torques and speeds: input and output torques, the torque distribution ratio (TDR) over
  time with the windows where it is measured (bench: ``bench.window_drive`` and
  ``window_coast``, labelled with their modes and the measured TDRs of ``[experiment]``;
  vehicle: the last :data:`~drivedyn.library.differentials.scenarios.WINDOW_FRACTION` of each
  held level, as ``drivedyn vehicle`` analyses them), the housing and output speeds [rpm] and
  the relative speeds;
* axial motion, washers and losses: axial travel of the gears (``axial_bodies``, change since
  the start), normal force and mean pressure of each thrust washer, and the dissipated power
  of the washers, of each element group (``element_groups``) and in total;
* with flexible parts (``[flexible]``): the largest von Mises stress of the case, the washers
  and each output shaft over time, and the shafts' torques.

Torques: vehicle configuration, the torques the outputs deliver to the axles (minus the speed
drivers' torques) and the engine torque on the housing; bench, the applied torque on the
loaded output, the speed-control driver's torque on the other and the torque holding the
housing.
"""

from __future__ import annotations

from typing import Any

from drivedyn.library.dashboards import Curve, Dashboard, Page, Panel, Term, Window
from drivedyn.library.differentials.base import Differential
from drivedyn.library.differentials.scenarios import level_windows

_Z = 2  # the outputs and the housing turn about global z


def _speed(body: str) -> Term:
    return Term(f"{body}.angular_velocity", _Z)


def _vehicle_torques(diff: Differential, p: Any) -> tuple[Panel, Panel]:
    first, second = diff.outputs
    t1 = Term(f"{first.name}_speed.torque", coefficient=-1.0)
    t2 = Term(f"{second.name}_speed.torque", coefficient=-1.0)
    torques = Panel("engine torque on the housing and output torques to the axles", "torque",
                    "N m", (Curve("housing (engine)", (Term("engine_torque.torque_z"),),
                                  style="k"),
                            Curve(first.label, (t1,)), Curve(second.label, (t2,)),
                            Curve(f"{first.name} + {second.name}", (t1, t2), style="k:")))
    levels = p.vehicle.torque_levels
    windows = tuple(Window(w0, w1, f"{levels[i]:g} N m" + (" back" if back else ""))
                    for _, w0, w1, i, back in level_windows(p))
    tdr = Panel("torque distribution ratio (favoured / other output torque)", "TDR", "1",
                (Curve("larger / smaller output torque", (t1,), over=(t2,),
                       ratio="larger_over_smaller"),),
                windows=windows,
                note="shaded: analysis window of each held level, its TDR written above")
    return torques, tdr


def _bench_torques(diff: Differential, p: Any) -> tuple[Panel, Panel]:
    side = p.scenario.modes or diff.sides[0]
    loaded, other = diff.output(side), diff.other(side)
    applied = Term("applied_torque.torque_z")
    resistant = Term("speed_control.torque")
    torques = Panel("bench torques", "torque", "N m",
                    (Curve(f"applied ({loaded.label})", (applied,)),
                     Curve(f"resistant ({other.label})", (resistant,)),
                     Curve("holding the housing", (Term("hold_housing.torque"),), style="k")))
    drive, coast = diff.side_modes[side]
    measured = {int(k.removeprefix("mode")): v for k, v in p.experiment.tdr.items()}
    windows = tuple(
        Window(*win, f"mode {m}", measured.get(m))
        for m, win in ((drive, p.bench.window_drive), (coast, p.bench.window_coast)))
    tdr = Panel("torque distribution ratio (applied / resistant torque)", "TDR", "1",
                (Curve("|applied / resistant|", (applied,), over=(resistant,),
                       ratio="magnitude"),),
                windows=windows,
                note="shaded: TDR windows of the modes (mean above); dashed: measured TDR")
    return torques, tdr


def _speeds(diff: Differential) -> tuple[Panel, Panel]:
    first, second = diff.outputs
    speeds = Panel("speeds", "speed", "rad/s",
                   (Curve("housing", (_speed("housing"),), style="k"),
                    *(Curve(o.label, (_speed(o.body),)) for o in diff.outputs)),
                   display="rpm")
    relative = Panel("relative speeds", "speed", "rad/s",
                     (Curve(f"{second.name} - {first.name}",
                            (_speed(second.body), Term(f"{first.body}.angular_velocity", _Z,
                                                       -1.0))),
                      *(Curve(f"{o.name} - housing",
                              (_speed(o.body), Term("housing.angular_velocity", _Z, -1.0)))
                        for o in diff.outputs)),
                     display="rpm")
    return speeds, relative


def _axial_and_losses(diff: Differential) -> tuple[Panel, ...]:
    axial = Panel("axial travel of the gears (since the start)", "travel", "m",
                  tuple(Curve(label, (Term(f"{body}.position", _Z),), relative=True)
                        for body, label in diff.axial_bodies))
    loads = Panel("thrust washers: normal force", "force", "N",
                  tuple(Curve(label, (Term(f"{w}.normal_force"),))
                        for w, label in diff.washers.items()))
    pressures = Panel("thrust washers: mean pressure", "pressure", "Pa",
                      tuple(Curve(label, (Term(f"{w}.pressure"),))
                            for w, label in diff.washers.items()))
    washers = tuple(Term(f"{w}.dissipated_power") for w in diff.washers)
    groups = tuple(Curve(label, tuple(Term(f"{pat}.dissipated_power") for pat in patterns))
                   for label, patterns in diff.element_groups)
    losses = Panel("dissipated power by element group", "power", "W",
                   (Curve("thrust washers", washers), *groups,
                    Curve("total", (Term("*.dissipated_power"),), style="k")))
    return axial, loads, pressures, losses


def _stresses(diff: Differential, p: Any) -> tuple[Panel, ...]:
    """Stress histories of the flexible parts ``p.flexible`` switches on: the largest von
    Mises stress of the case, of the washers and of each output shaft (over its beam
    elements), and the shafts' torques at their gear ends. Empty for a rigid model."""
    fx = getattr(p, "flexible", None)
    if fx is None:
        return ()
    curves = []
    if getattr(fx, "case", False):
        curves.append(Curve("case", (Term("case.max_von_mises", reduce="max"),)))
    if fx.washers:
        curves.append(Curve("washers (largest)", (Term("washer_*.max_von_mises",
                                                        reduce="max"),)))
    shafts = diff.outputs if getattr(fx, "shafts", False) else ()
    curves += [Curve(f"{o.label} shaft", (Term(f"{o.body}_shaft.e*.von_mises", reduce="max"),))
               for o in shafts]
    if not curves:
        return ()
    panels = [Panel("largest von Mises stress of the flexible parts", "stress", "Pa",
                    tuple(curves))]
    if shafts:
        panels.append(Panel("output shaft torques (gear end)", "torque", "N m",
                            tuple(Curve(f"{o.label} shaft", (Term(f"{o.body}_shaft.e0.torque"),))
                                  for o in shafts)))
    return tuple(panels)


def differential_dashboard(diff: Differential, p: Any) -> Dashboard:
    """The dashboard of a run of differential ``diff`` with validated parameters ``p``
    (its scenario: ``p.scenario.kind``, ``"vehicle"`` or ``"bench"``); a third page with
    the stresses of the flexible parts, if the model has any."""
    bench = p.scenario.kind == "bench"
    torques, tdr = _bench_torques(diff, p) if bench else _vehicle_torques(diff, p)
    where = "bench" if bench else "vehicle configuration"
    pages = [Page("torques and speeds", (torques, tdr, *_speeds(diff))),
             Page("axial motion, thrust washers and losses", _axial_and_losses(diff))]
    stresses = _stresses(diff, p)
    if stresses:
        pages.append(Page("stresses of the flexible parts", stresses))
    return Dashboard(name=f"dashboard_{diff.library}", title=f"{diff.title}, {where}",
                     pages=tuple(pages))
