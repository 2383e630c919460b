"""The static torsion test of a ladder frame, and the closed form of a rectangular frame.

**Test** (the usual bench test of a frame or body shell, here at the rail ends): the bare
frame (no body) held by ball joints at both rear rail ends and at the centre-line node of the
cross member farthest forward, equal and opposite vertical forces ``+-F`` at the front rail
ends (up on the left), ``F = T / track``: the frame carries the torque ``T`` between its front
and rear ends. The twist is the difference of the vertical displacements of the front rail
ends over the track (the rear ends do not move), ``theta = (w_FL - w_FR) / track``, and the
torsional stiffness ``K = T / theta`` in N m/deg. The frame is symmetric about its centre
line and the load antisymmetric, so the centre-line support carries no force (it only holds
the pitch of the frame about the rear supports) and the in-plane supports none either; the
small load keeps the response linear (the geometrically exact beams would follow large
twists too).

**Closed form**: a rectangular frame, two rails of length ``L`` at ``track = b`` and two cross
members at the rail ends, rigid corners, loaded as above. The four corner forces alternate,
``-F, +F`` on the left rail, ``+F, -F`` on the right one. Symmetry (the frame and the
anti-symmetric load under the mirrors ``y -> -y`` and ``x -> L - x``) makes every bending
moment vanish at mid-member, so a rail carries a constant shear ``V_r`` and a moment
``V_r (x - L/2)``, a cross member ``V_c = F - V_r`` and ``V_c y``; corner equilibrium turns
the rail's end moment into the cross member's torque ``T_c = V_r L / 2`` and the cross
member's end moment into the rail's torque ``T_r = V_c b / 2``. The strain energy (bending,
Timoshenko shear, Saint-Venant torsion) is ``U = V_r^2 A + V_c^2 B`` with::

    A = L^3 / (12 EI_r) + L / (kGA_r) + L^2 b / (4 GJ_c)
    B = b^3 / (12 EI_c) + b / (kGA_c) + b^2 L / (4 GJ_r)

(``EI`` for bending in the vertical plane, ``kGA`` the vertical shear stiffness). Least work
(``dU/dV_r = 0``) gives ``U = F^2 A B / (A + B)``, and ``U = T theta / 2`` with ``T = F b``::

    K = T / theta = (b^2 / 2) (1 / A + 1 / B)   [N m/rad]

two load paths in parallel: rail bending with cross-member torsion (``A``), rail torsion with
cross-member bending (``B``). Limits: rigid cross members give ``2 GJ_r / L`` (two rails
twisting) and ``6 EI_r b^2 / L^3`` (two rails bending as guided beams).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from drivedyn.elements.joints import Spherical
from drivedyn.elements.loads import Force
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.chassis.frame import add_ladder_frame
from drivedyn.library.vehicles.chassis.schema import LadderFrameFile
from drivedyn.model.compile import compile_model
from drivedyn.model.model import Model, State
from drivedyn.model.spec import GROUND, Spec
from drivedyn.solver.statics import solve_static
from drivedyn.solver.system import element_outputs

DEFAULT_TORQUE = 100.0  # [N m]: hundredths of a degree on a frame, a linear response


@dataclass(frozen=True)
class TorsionTest:
    """Result of :func:`torsion_test`.

    Attributes:
        stiffness: torsional stiffness ``T / theta`` [N m/deg].
        torque: the torque applied [N m].
        twist: front-to-rear twist ``theta`` [deg].
        centre_reaction: vertical force on the centre-line support [N] (zero for a symmetric
            frame: a check of the test).
        elements: number of beam elements of the frame.
    """

    stiffness: float
    torque: float
    twist: float
    centre_reaction: float
    elements: int


def refined(p: LadderFrameFile, factor: int) -> LadderFrameFile:
    """``p`` with ``factor`` times as many elements per segment."""
    mesh = p.mesh.model_copy(update={"elements_per_segment": p.mesh.elements_per_segment
                                     * int(factor)})
    return p.model_copy(update={"mesh": mesh})


def torsion_test(p: LadderFrameFile, torque: float = DEFAULT_TORQUE) -> TorsionTest:
    """The static torsion test of the bare frame ``p`` (module docstring) under ``torque``
    [N m], solved with :func:`~drivedyn.solver.statics.solve_static`."""
    if not (math.isfinite(torque) and torque > 0.0):
        raise ModelError(f"torsion_test.torque: must be > 0 N m, got {torque!r}")
    ahead = max(range(len(p.cross_members)), key=lambda k: p.cross_members[k].x)
    if not p.cross_members[ahead].x > 0.0:
        raise ModelError("torsion test: needs a cross member ahead of the rear rail ends "
                         f"(cross_members x = {[c.x for c in p.cross_members]} m)")
    sp = Spec()
    fr = add_ladder_frame(sp, "frame", p, carry_body=False)
    cm = fr.cross_members[ahead]
    centre = cm[len(cm) // 2]
    supports = {"rear_left": fr.left[0], "rear_right": fr.right[0], "centre": centre}
    for label, node in supports.items():
        sp.add_marker(f"{label}.ground", GROUND, position=sp.nodes[node].position)
        sp.add_marker(f"{label}.frame", node)
        sp.add(Spherical(f"{label}.support", f"{label}.ground", f"{label}.frame"))
    F = torque / p.rails.track
    for label, node, sign in (("front_left", fr.left[-1], 1.0),
                              ("front_right", fr.right[-1], -1.0)):
        sp.add_marker(f"{label}.load", node)
        sp.add(Force(f"{label}.force", f"{label}.load", (0.0, 0.0, sign * F)))
    model = compile_model(sp)
    st = solve_static(model, t=0.0)
    idx = model.node_index
    w_fl = st.x[idx[fr.left[-1]], 2] - model.state0.x[idx[fr.left[-1]], 2]
    w_fr = st.x[idx[fr.right[-1]], 2] - model.state0.x[idx[fr.right[-1]], 2]
    theta = math.degrees((w_fl - w_fr) / p.rails.track)
    centre_reaction = _reaction_z(model, st, "centre.support")
    return TorsionTest(torque / theta, torque, theta, centre_reaction, len(fr.elements))


def _reaction_z(model: Model, st: State, joint: str) -> float:
    """The vertical reaction force of a joint [N] (its ``force_z`` output)."""
    return float(element_outputs(model, st)[joint]["force_z"])


def torsional_stiffness(p: LadderFrameFile, torque: float = DEFAULT_TORQUE) -> float:
    """The frame's static torsional stiffness [N m/deg] (:func:`torsion_test`)."""
    return torsion_test(p, torque).stiffness


def rectangle_frame_stiffness(p: LadderFrameFile) -> float:
    """Closed-form torsional stiffness [N m/deg] of the rectangular frame of ``p``'s rails
    and the section of its first cross member, cross members at both rail ends (module
    docstring)."""
    mat = p.material.material()
    r = p.rails.section.beam_section(mat).properties(mat).stiffness
    c = p.cross_members[0].section.beam_section(mat).properties(mat).stiffness
    # stiffness = [EA, GA_y, GA_z, GJ, EI_y, EI_z]: z vertical, EI_y the vertical bending
    L, b = p.rails.length, p.rails.track
    A = L**3 / (12.0 * r[4]) + L / r[2] + L**2 * b / (4.0 * c[3])
    B = b**3 / (12.0 * c[4]) + b / c[2] + b**2 * L / (4.0 * r[3])
    return 0.5 * b**2 * (1.0 / A + 1.0 / B) * math.pi / 180.0


def rectangle_frame(p: LadderFrameFile) -> LadderFrameFile:
    """``p`` reduced to the rectangular frame of the closed form: its rails, and two cross
    members of the first cross member's section at the rail ends; no body, no stations."""
    sec = p.cross_members[0].section
    cms = [{"x": 0.0, "section": sec}, {"x": p.rails.length, "section": sec}]
    data = p.model_dump()
    data.update(cross_members=cms, body=None, mesh={**data["mesh"], "stations": []})
    return LadderFrameFile.model_validate(data)


