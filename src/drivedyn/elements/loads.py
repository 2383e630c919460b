"""Applied loads on markers (families ``force``, ``torque``).

A :class:`Force` ``F(t) = vector f(t)`` [N] acts at a marker's origin; a :class:`Torque`
``T(t) = vector f(t)`` [N m] on the marker's body. ``frame="global"`` keeps the direction
fixed in space; ``frame="marker"`` makes it follow the marker (a follower load). Their power
``F . v_marker`` or ``T . omega`` is counted as work supplied in the energy balance.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.framework.building import make_group, node_dofs, what_of
from drivedyn.elements.framework.checks import unit_of
from drivedyn.elements.framework.contract import local_arrays_at, local_size
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.primitives import cross, mat_skew, mtv, mv, set_skew, skew_skew
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.errors import ModelError

_L6 = local_size.py_func(6, 0)  # the plain function: nothing compiled at import
#: entries of a load group's work buffer (its last parameter, ``work``)
WORK_SIZE = _L6 + sc.WORKSPACE_SIZE


@njit(cache=True)
def load_kernel(
    is_torque, follower, p, Rm, vec, tfid, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, WORK_SIZE)  # the work arrays are views of the group's buffer
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (ws, wv) = (local_arrays_at(buf, 0, 6, 0), sc.workspace_at(buf, _L6))
    full = sc.full_pass(want, mode)
    rq, _, _, _, K, _ = L
    for e in range(sc.count(C)):
        n = sc.node(C, e, 0)
        Rn = R[n]
        d0 = sc.first_dof(C, e)
        f = tfv[tfid[e], 0]
        for a in range(3):
            wv[0, a] = vec[e, a] * f  # load vector: global, or marker frame if follower
        mv(Rm[e], wv[0], wv[1])  # node-frame components of a follower load
        for a in range(6):
            rq[a] = 0.0
        if full:
            K[:, :] = 0.0
        Om = v[d0 + 3 : d0 + 6]
        if is_torque:
            if follower[e]:
                mb = wv[1]
            else:
                mb = wv[2]
                mtv(Rn, wv[0], mb)  # body components of a fixed-direction torque
                if full:
                    # d(-R^T T)/dtheta = -(R^T T)~
                    set_skew(mb, ws[0])
                    for i in range(3):
                        for j in range(3):
                            K[3 + i, 3 + j] = -ws[0, i, j]
            for a in range(3):
                rq[3 + a] = -mb[a]
            power = mb[0] * Om[0] + mb[1] * Om[1] + mb[2] * Om[2]
            mv(Rn, mb, wv[3])  # reported torque, global
        else:
            pe = p[e]
            Fg = wv[3]
            if follower[e]:
                Fb = wv[1]
                mv(Rn, Fb, Fg)
                if full:
                    mat_skew(Rn, Fb, 1.0, K, 0, 3)  # d(-R Fb)/dtheta = R Fb~
            else:
                Fb = wv[2]
                for a in range(3):
                    Fg[a] = wv[0, a]
                mtv(Rn, Fg, Fb)
                if full:
                    skew_skew(pe, Fb, ws[0], -1.0, K, 3, 3)  # -p~ (R^T F)~
            cross(pe, Fb, wv[4])
            for a in range(3):
                rq[a] = -Fg[a]
                rq[3 + a] = -wv[4, a]
            cross(Om, pe, wv[5])
            mv(Rn, wv[5], wv[6])
            power = 0.0
            for a in range(3):
                power += Fg[a] * (v[d0 + a] + wv[6, a])
        sc.scatter(C, L, e, 1, full)
        sc.energy(C, e, 0.0, 0.0, power, 0.0)
        sc.report(C, e, (wv[3, 0], wv[3, 1], wv[3, 2], power))


@dataclass(frozen=True)
class Force(ElementSpec):
    """Force ``vector * function(t)`` [N] applied at the origin of ``marker``.

    Attributes:
        name: unique element name.
        marker: marker on a body or node (not the ground).
        vector: (3,) direction and magnitude [N].
        function: time function scaling the vector (number, TimeFunction or dict); default 1.
        frame: ``"global"`` (fixed direction) or ``"marker"`` (follows the marker).
    """

    name: str
    marker: str
    vector: Any = (0.0, 0.0, 0.0)
    function: Any = 1.0
    frame: str = "global"
    family: ClassVar[str] = "force"
    units: ClassVar[dict[str, str]] = {"vector": "N"}
    is_torque: ClassVar[bool] = False

    def markers(self) -> tuple[str, ...]:
        return (self.marker,)

    def validate(self) -> None:
        what = what_of(self)
        if self.frame not in ("global", "marker"):
            raise ModelError(f"{what}.frame: expected 'global' or 'marker', got {self.frame!r}")
        vec = np.asarray(self.vector, dtype=float)
        if vec.shape != (3,) or not np.all(np.isfinite(vec)):
            raise ModelError(f"{what}.vector: expected 3 finite numbers "
                             f"[{unit_of(self, 'vector')}], got {self.vector!r}")


@dataclass(frozen=True)
class Torque(Force):
    """Torque ``vector * function(t)`` [N m] applied on the body of ``marker``."""

    family: ClassVar[str] = "torque"
    units: ClassVar[dict[str, str]] = {"vector": "N m"}
    is_torque: ClassVar[bool] = True


class LoadFamily(Family):
    """Registry entry of :class:`Force` (``is_torque=False``) or :class:`Torque`."""

    def __init__(self, name: str, is_torque: bool) -> None:
        self.name = name
        self.is_torque = is_torque

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        p = np.zeros((nel, 3))
        Rm = np.zeros((nel, 3, 3))
        lnodes = np.zeros((nel, 1), np.int64)
        for e, s in enumerate(specs):
            what = what_of(s)
            lnodes[e, 0], p[e], Rm[e] = ctx.marker(s.marker, what)
            if lnodes[e, 0] == ctx.nn:
                raise ModelError(f"{what}: marker {s.marker!r} is on the ground; a load must act "
                                 "on a body or node")
        tfid = np.array([ctx.time_function(s.function) for s in specs], np.int64)
        follower = np.array([s.frame == "marker" for s in specs], dtype=np.bool_)
        vec = np.array([np.asarray(s.vector, float) for s in specs]).reshape(nel, 3)
        kind, unit = ("torque", "N m") if self.is_torque else ("force", "N")
        return make_group(
            self.name, specs, load_kernel,
            (self.is_torque, follower, p, Rm, vec, tfid, np.zeros(WORK_SIZE)), lnodes,
            node_dofs(ctx, lnodes),
            (*((f"{kind}_{c}", unit, f"applied {kind}, global {c}") for c in "xyz"),
             ("power", "W", "power supplied by the load")),
        )


register(LoadFamily("force", False))
register(LoadFamily("torque", True))
