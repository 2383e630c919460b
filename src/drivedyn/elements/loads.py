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

from drivedyn.elements.base import MODE_ACC, ElementSpec, Family, Group, register, scatter_local
from drivedyn.model.spec import ModelError


@njit(cache=True, inline="always")
def _load_kernel_element(P, I, S, Cc, O, W, full):
    is_torque, follower, p, Rm, vec, tfid = P
    lnodes, dofs, kmap, eoff = I
    x, R, v, vd, lam, es, tfv, t = S
    Tn, cM, cC, cK, mode, want = Cc
    r, rabs, data, eout, aux = O
    nel, rq, rl, M, C, K, G = W
    for e in range(nel):
        n = lnodes[e, 0]
        Rn = R[n]
        d0 = dofs[e, 0]
        f = tfv[tfid[e], 0]
        loc = Rm[e] @ vec[e] * f  # node-frame components if follower
        rq[:] = 0.0
        K[:, :] = 0.0
        Om = v[d0 + 3 : d0 + 6]
        if is_torque:
            if follower[e]:
                mb = loc
            else:
                mb = Rn.T @ (vec[e] * f)
                if full:
                    # d(-R^T T)/dtheta = -(R^T T)~
                    K[3, 4] = mb[2]
                    K[3, 5] = -mb[1]
                    K[4, 3] = -mb[2]
                    K[4, 5] = mb[0]
                    K[5, 3] = mb[1]
                    K[5, 4] = -mb[0]
            rq[3:6] = -mb
            power = mb[0] * Om[0] + mb[1] * Om[1] + mb[2] * Om[2]
            Fg = np.zeros(3)
        else:
            pe = p[e]
            if follower[e]:
                Fg = Rn @ loc
                Fb = loc
                if full:
                    # d(-R Fb)/dtheta = R Fb~
                    S = np.zeros((3, 3))
                    S[0, 1] = -Fb[2]
                    S[0, 2] = Fb[1]
                    S[1, 0] = Fb[2]
                    S[1, 2] = -Fb[0]
                    S[2, 0] = -Fb[1]
                    S[2, 1] = Fb[0]
                    K[0:3, 3:6] = Rn @ S
            else:
                Fg = vec[e] * f
                Fb = Rn.T @ Fg
                if full:
                    # d(-p x R^T F)/dtheta = -p~ (R^T F)~
                    P = np.zeros((3, 3))
                    P[0, 1] = -pe[2]
                    P[0, 2] = pe[1]
                    P[1, 0] = pe[2]
                    P[1, 2] = -pe[0]
                    P[2, 0] = -pe[1]
                    P[2, 1] = pe[0]
                    S = np.zeros((3, 3))
                    S[0, 1] = -Fb[2]
                    S[0, 2] = Fb[1]
                    S[1, 0] = Fb[2]
                    S[1, 2] = -Fb[0]
                    S[2, 0] = -Fb[1]
                    S[2, 1] = Fb[0]
                    K[3:6, 3:6] = -(P @ S)
            mb = np.cross(pe, Fb)
            rq[0:3] = -Fg
            rq[3:6] = -mb
            vm = v[d0 : d0 + 3] + Rn @ np.cross(Om, pe)
            power = Fg[0] * vm[0] + Fg[1] * vm[1] + Fg[2] * vm[2]
        if full:
            scatter_local(rq, rl, M, C, K, G, 1, lnodes[e], dofs[e], kmap[e], Tn,
                          cM, cC, cK, mode, want, r, rabs, data)
        else:
            scatter_local(rq, rl, M, C, K, G, 1, lnodes[e], dofs[e], kmap[e], Tn,
                          cM, cC, cK, mode, False, r, rabs, data)
        if is_torque:
            Tg = Rn @ mb
            for a in range(3):
                aux[e, a] = Tg[a]
        else:
            for a in range(3):
                aux[e, a] = Fg[a]
        aux[e, 3] = power
        eout[e, 0] = 0.0
        eout[e, 1] = 0.0
        eout[e, 2] = power
        eout[e, 3] = 0.0


@njit(cache=True)
def load_kernel(
    is_torque, follower, p, Rm, vec, tfid,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    nel = vec.shape[0]
    rq = np.zeros(6)
    rl = np.zeros(0)
    M = np.zeros((6, 6))
    C = np.zeros((6, 6))
    K = np.zeros((6, 6))
    G = np.zeros((0, 6))
    P = (is_torque, follower, p, Rm, vec, tfid)
    I = (lnodes, dofs, kmap, eoff)
    S = (x, R, v, vd, lam, es, tfv, t)
    Cc = (Tn, cM, cC, cK, mode, want)
    O = (r, rabs, data, eout, aux)
    W = (nel, rq, rl, M, C, K, G)
    if want or mode == MODE_ACC:
        _load_kernel_element(P, I, S, Cc, O, W, True)
    else:
        _load_kernel_element(P, I, S, Cc, O, W, False)



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
    is_torque: ClassVar[bool] = False

    def markers(self) -> tuple[str, ...]:
        return (self.marker,)

    def validate(self) -> None:
        what = f"{type(self).__name__} {self.name!r}"
        if self.frame not in ("global", "marker"):
            raise ModelError(f"{what}.frame: expected 'global' or 'marker', got {self.frame!r}")
        vec = np.asarray(self.vector, dtype=float)
        if vec.shape != (3,) or not np.all(np.isfinite(vec)):
            raise ModelError(f"{what}.vector: expected 3 finite numbers, got {self.vector!r}")


@dataclass(frozen=True)
class Torque(Force):
    """Torque ``vector * function(t)`` [N m] applied on the body of ``marker``."""

    family: ClassVar[str] = "torque"
    is_torque: ClassVar[bool] = True


class _LoadFamily(Family):
    is_torque = False

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        p = np.zeros((nel, 3))
        Rm = np.zeros((nel, 3, 3))
        lnodes = np.zeros((nel, 1), np.int64)
        dofs = np.zeros((nel, 6), np.int64)
        tfid = np.zeros(nel, np.int64)
        follower = np.array([s.frame == "marker" for s in specs], dtype=np.bool_)
        for e, s in enumerate(specs):
            what = f"{type(s).__name__} {s.name!r}"
            n, p[e], Rm[e] = ctx.marker(s.marker, what)
            if n == ctx.nn:
                raise ModelError(f"{what}: marker {s.marker!r} is on the ground; a load must act "
                                 "on a body or node")
            lnodes[e, 0] = n
            dofs[e] = ctx.local_dofs([n], 0, 0)
            tfid[e] = ctx.time_function(s.function)
        vec = np.array([np.asarray(s.vector, float) for s in specs]).reshape(nel, 3)
        kind = "torque" if self.is_torque else "force"
        unit = "N m" if self.is_torque else "N"
        return Group(
            family=self.name, names=[s.name for s in specs], kernel=load_kernel,
            params=(self.is_torque, follower, p, Rm, vec, tfid),
            lnodes=lnodes, nmult=0, dofs=dofs, eoff=np.zeros(nel, np.int64),
            aux_names=(f"{kind}_x", f"{kind}_y", f"{kind}_z", "power"),
            aux_units=(unit, unit, unit, "W"),
            aux_desc=(f"applied {kind}, global x", f"applied {kind}, global y",
                      f"applied {kind}, global z", "power supplied by the load"),
            supplies_power=True,
        )

    def tangent_cases(self):
        from drivedyn.elements import _tangent_cases as tc

        return [lambda: tc.load_case(self.is_torque, "global"),
                lambda: tc.load_case(self.is_torque, "marker")]


class ForceFamily(_LoadFamily):
    name = "force"


class TorqueFamily(_LoadFamily):
    name = "torque"
    is_torque = True


register(ForceFamily())
register(TorqueFamily())
