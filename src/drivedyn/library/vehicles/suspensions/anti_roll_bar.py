"""Anti-roll bar as its torsional equivalent: two rigid halves and a torsional spring.

Each half of the bar (its torsion tube's half and its lever) is a rigid body hinged to the
chassis on the bar's axis (the vehicle's y axis through the file's ``pivot``); a
:class:`~drivedyn.elements.TorsionalSpringDamper` between the halves on that axis carries the
bar's torsion, ``T = rate * (phi_left - phi_right)`` (its rate is the bar's ``G J / L``); a
drop link (a rigid body: ball joint at the lower arm, universal joint at the lever, its
axes across the link so that it cannot spin) joins each lever's end to its lower arm. The
bar's bending and the drop links' compliance are left out: in roll the bar twists, in heave
both halves turn together and the spring carries nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drivedyn.elements import Hinge, Spherical, TorsionalSpringDamper, Universal
from drivedyn.elements.framework.visuals import link
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.suspensions.double_wishbone import Corner, mirrored_inertia
from drivedyn.library.vehicles.suspensions.geometry import (
    Mount,
    chassis_marker,
    frame,
    marker_at,
    on_side,
    rod_frame,
    unit,
)
from drivedyn.library.vehicles.suspensions.macpherson import MacPhersonCorner
from drivedyn.library.vehicles.suspensions.schema import DoubleWishboneFile, MacPhersonFile
from drivedyn.model.spec import Spec

Y = np.array([0.0, 1.0, 0.0])
#: the bar's axis frame: z along the vehicle's y
R_BAR = frame(np.array([1.0, 0.0, 0.0]), Y)


@dataclass
class AntiRollBar:
    """Names of a built anti-roll bar.

    Attributes:
        halves: (left, right) half bodies.
        drop_links: (left, right) drop-link bodies.
        spring: the torsional spring-damper (its ``torque`` output is the bar's torque).
        hinges: (left, right) hinges of the halves on the chassis.
    """

    halves: tuple[str, str]
    drop_links: tuple[str, str]
    spring: str
    hinges: tuple[str, str]


def add_anti_roll_bar(sp: Spec, prefix: str, p: DoubleWishboneFile | MacPhersonFile,
                      mount: Mount, left: Corner | MacPhersonCorner,
                      right: Corner | MacPhersonCorner) -> AntiRollBar:
    """Build the anti-roll bar of suspension ``p`` (either type) between the lower arms of
    its ``left`` and ``right`` corners (see the module docstring).

    Raises:
        ModelError: ``p`` has no anti-roll bar, or its geometry is degenerate (a drop link
            along its lever, a lever of zero length): the message names the key and value.
    """
    bar = p.anti_roll_bar
    if bar is None:
        raise ModelError(f"anti-roll bar {prefix!r}: the suspension has no [anti_roll_bar]")
    loc = np.asarray(p.location)
    base = {k: loc + np.asarray(getattr(bar, k)) for k in ("pivot", "lever_end",
                                                             "drop_link_arm")}
    r = base["lever_end"] - base["pivot"]
    lever = float(np.linalg.norm(r - (r @ Y) * Y))
    if lever < 1e-3:
        raise ModelError(f"anti_roll_bar.lever_end = {list(bar.lever_end)} m: on the bar's "
                         f"axis (lever {lever:.3g} m)")
    dl = unit(base["drop_link_arm"] - base["lever_end"], "anti_roll_bar.drop_link_arm: drop "
              "link")
    if abs(dl @ np.cross(Y, r)) / lever < 1e-3:  # across the lever end's path: no grip
        raise ModelError(f"anti_roll_bar.drop_link_arm = {list(bar.drop_link_arm)} m: the drop "
                         "link is along the lever (it cannot turn the bar)")
    centre = base["pivot"] * np.array([1.0, 0.0, 1.0])
    halves, links, hinges = [], [], []
    for corner in (left, right):
        side = corner.side
        pts = {k: on_side(v, side) for k, v in base.items()}
        s = side[0]
        com = (on_side(loc + np.asarray(bar.half.com), side) if bar.half.com is not None
               else (pts["pivot"] + pts["lever_end"]) / 2.0)
        half = sp.add_rigid_body(f"{prefix}_{side}_half", bar.half.mass,
                                 mirrored_inertia(bar.half.inertia, np.eye(3), np.eye(3), side),
                                 position=com)
        c = chassis_marker(sp, mount, f"{prefix}_{side}_pivot", pts["pivot"], R_BAR)
        h = marker_at(sp, f"{prefix}_{s}_half_pivot", half, pts["pivot"], R_BAR)
        hinges.append(sp.add(Hinge(f"{prefix}_{side}_pivot", c, h)).name)
        marker_at(sp, f"{prefix}_{s}_half_centre", half, centre, R_BAR)
        R_dl = rod_frame(pts["lever_end"], pts["drop_link_arm"], f"{prefix} drop link")
        R_dl_left = rod_frame(base["lever_end"], base["drop_link_arm"], f"{prefix} drop link")
        dcom = (on_side(loc + np.asarray(bar.drop_link.com), side)
                if bar.drop_link.com is not None
                else (pts["lever_end"] + pts["drop_link_arm"]) / 2.0)
        drop = sp.add_rigid_body(f"{prefix}_{side}_drop_link", bar.drop_link.mass,
                                 mirrored_inertia(bar.drop_link.inertia, R_dl_left, R_dl, side),
                                 position=dcom, rotation=R_dl)
        lv = marker_at(sp, f"{prefix}_{s}_lever_end", half, pts["lever_end"], R_dl)
        d_top = marker_at(sp, f"{prefix}_{s}_drop_top", drop, pts["lever_end"], R_dl)
        sp.add(Universal(f"{prefix}_{side}_drop_top", lv, d_top))
        d_bot = marker_at(sp, f"{prefix}_{s}_drop_bottom", drop, pts["drop_link_arm"])
        arm = marker_at(sp, f"{prefix}_{s}_arm", corner.lower_arm, pts["drop_link_arm"])
        sp.add(Spherical(f"{prefix}_{side}_drop_bottom", arm, d_bot))
        sp.add_visual(link(h, lv, 0.012, role="part", label=half))
        sp.add_visual(link(d_top, d_bot, 0.008, role="part", label=drop))
        halves.append(half)
        links.append(drop)
    sp.add_visual(link(f"{prefix}_l_half_pivot", f"{prefix}_r_half_pivot", 0.012, role="part",
                       label=f"{prefix} bar"))
    spring = sp.add(TorsionalSpringDamper(f"{prefix}_torsion", f"{prefix}_r_half_centre",
                                          f"{prefix}_l_half_centre", stiffness=bar.rate,
                                          damping=bar.damping)).name
    return AntiRollBar((halves[0], halves[1]), (links[0], links[1]), spring,
                       (hinges[0], hinges[1]))
