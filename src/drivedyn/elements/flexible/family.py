"""The reduced flexible body spec and its registry entry (family ``flexible_body``).

A :class:`FlexibleBody` is a meshed part reduced by Craig-Bampton
(:func:`drivedyn.fe.craig_bampton`) and mounted on a marker: its first interface (the
mounting face, a rigid spider) moves with the marker's frame, which is the floating frame;
the part adds its full inertia (rigid and elastic, coupled) to the marker's node, so it can
be mounted on a plain node (a free body) or on a rigid body (a washer on a gear, a case
bolted to a housing). Its elastic coordinates are carried by coordinate nodes (see
:mod:`~drivedyn.elements.flexible.kernel`); :func:`drivedyn.model.flexible.add_flexible_body`
creates them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from drivedyn.elements.flexible.kernel import flexible_body_kernel, work_size
from drivedyn.elements.framework.building import make_group, what_of
from drivedyn.elements.framework.checks import check_param
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.errors import ModelError, did_you_mean

#: frequency of the decoupled spring-mass that holds the unused slots of coordinate nodes,
#: relative to the part's highest reduced frequency (above every retained mode, and of the
#: same scale as the part's own matrix entries so the iteration matrix stays balanced)
HOLD_RATIO = 10.0


@dataclass(frozen=True)
class FlexibleBody(ElementSpec):
    """A reduced flexible body in a floating frame of reference.

    Attributes:
        name: unique element name.
        marker: the mounting marker: the part frame's interface 0 (its rigid spider point
            and the part axes) coincides with this marker's frame.
        part: a :class:`~drivedyn.fe.reduction.ReducedPart`.
        coordinates: names of the ``ceil(nq / 3)`` coordinate nodes (plain nodes) whose
            translation slots hold the elastic coordinates ``q`` (their initial positions are
            the initial ``q``).
        damping: stiffness-proportional damping ``beta`` [s]: ``D = beta Kr``.
    """

    name: str
    marker: str
    part: Any
    coordinates: tuple[str, ...]
    damping: float = 0.0
    family: ClassVar[str] = "flexible_body"
    units: ClassVar[dict[str, str]] = {"damping": "s"}

    def markers(self) -> tuple[str, ...]:
        return (self.marker,)

    def validate(self) -> None:
        what = what_of(self)
        nq = getattr(self.part, "nq", None)
        if nq is None or not hasattr(self.part, "Kr"):
            raise ModelError(f"{what}.part: expected a ReducedPart (drivedyn.fe.craig_bampton), "
                             f"got {type(self.part).__name__}")
        need = math.ceil(nq / 3)
        if len(self.coordinates) != need:
            raise ModelError(f"{what}.coordinates: {nq} elastic coordinates need {need} "
                             f"coordinate nodes, got {len(self.coordinates)}")
        check_param(self, "damping", 0.0)


def flexible_body_named(spec: Any, name: str, what: str) -> FlexibleBody:
    """The :class:`FlexibleBody` element ``name`` of ``spec`` (elements that act on a part
    name it in their ``body``); :class:`ModelError` naming ``what`` otherwise."""
    bodies = {e.name: e for e in spec.elements if isinstance(e, FlexibleBody)}
    if name not in bodies:
        raise ModelError(f"{what}.body: no flexible body {name!r}{did_you_mean(name, bodies)}")
    return bodies[name]


def invariants(part: Any, p: np.ndarray, Rm: np.ndarray) -> dict[str, np.ndarray]:
    """Inertia invariants of ``part`` mounted at offset ``p`` (3,) and rotation ``Rm`` (3, 3)
    in the host node frame (see :mod:`~drivedyn.elements.flexible.kernel`)."""
    X = p + part.X @ Rm.T                                  # (n, 3)
    Phi = np.einsum("ij,njk->nik", Rm, part.Phi)           # (n, 3, nq)
    Ms = part.Ms
    mj = np.asarray(Ms.sum(axis=1)).ravel()
    MX = Ms @ X                                            # (n, 3)
    nq = Phi.shape[2]
    MPhi = np.stack([Ms @ Phi[:, d, :] for d in range(3)], axis=1) if nq else \
        np.zeros((X.shape[0], 3, 0))
    A = np.einsum("nb,ndk->bdk", X, MPhi)
    Q = np.einsum("nbk,ndl->bdkl", Phi, MPhi)
    return {
        "mass": float(mj.sum()), "S0": mj @ X, "Phib": np.einsum("n,ndk->dk", mj, Phi),
        "G0": X.T @ MX, "A": A, "Q": Q,
        "Qa": np.stack([Q[0, 1] - Q[1, 0], Q[0, 2] - Q[2, 0], Q[1, 2] - Q[2, 1]]),
        "Mqq": Q[0, 0] + Q[1, 1] + Q[2, 2], "X": X, "Phi": Phi,
    }


OUTPUTS = (("elastic_energy", "J", "strain energy of the part (1/2 q^T Kr q)"),)


class FlexibleBodyFamily(Family):
    """Registry entry of :class:`FlexibleBody`."""

    name = "flexible_body"

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        nqm = max(s.part.nq for s in specs)
        nnode = 1 + max(1, math.ceil(nqm / 3))
        lnodes = np.full((nel, nnode), ctx.nn, np.int64)
        arrays = {k: [] for k in ("mass", "S0", "Phib", "G0", "A", "Q", "Qa", "Mqq", "Kr",
                                  "Dr")}
        nqs = np.zeros(nel, np.int64)
        hold = np.zeros((nel, 2))
        mounts = []
        for e, s in enumerate(specs):
            what = what_of(s)
            node, p, Rm = ctx.marker(s.marker, what)
            if node == ctx.nn:
                raise ModelError(f"{what}: the mounting marker {s.marker!r} is on the ground; "
                                 "a part on the ground does not move (mount it on a node)")
            lnodes[e, 0] = node
            for j, cn in enumerate(s.coordinates):
                if cn not in ctx.node_index or cn in ctx.spec.bodies:
                    raise ModelError(f"{what}.coordinates: {cn!r} is not a plain node"
                                     f"{did_you_mean(cn, ctx.spec.nodes)}")
                lnodes[e, 1 + j] = ctx.node_index[cn]
            inv = invariants(s.part, p, Rm)
            nq = s.part.nq
            nqs[e] = nq

            def pad(a, shape):
                out = np.zeros(shape)
                out[tuple(slice(0, k) for k in a.shape)] = a
                return out

            arrays["mass"].append(inv["mass"])
            arrays["S0"].append(inv["S0"])
            arrays["Phib"].append(pad(inv["Phib"], (3, nqm)))
            arrays["G0"].append(inv["G0"])
            arrays["A"].append(pad(inv["A"], (3, 3, nqm)))
            arrays["Q"].append(pad(inv["Q"], (3, 3, nqm, nqm)))
            arrays["Qa"].append(pad(inv["Qa"], (3, nqm, nqm)))
            arrays["Mqq"].append(pad(inv["Mqq"], (nqm, nqm)))
            arrays["Kr"].append(pad(s.part.Kr, (nqm, nqm)))
            arrays["Dr"].append(pad(float(s.damping) * s.part.Kr, (nqm, nqm)))
            hm = float(np.mean(np.diag(inv["Mqq"]))) if nq else inv["mass"]
            w2 = float(np.max(np.linalg.eigvals(np.linalg.solve(inv["Mqq"], s.part.Kr)).real)
                       ) if nq else 1.0
            hold[e] = (hm, hm * HOLD_RATIO**2 * max(w2, 1e-12))
            mounts.append({"node": int(node), "X": inv["X"], "Phi": inv["Phi"]})
        params = tuple(np.ascontiguousarray(np.asarray(arrays[k], float)) for k in
                       ("mass", "S0", "Phib", "G0", "A", "Q", "Qa", "Mqq", "Kr", "Dr"))
        params = (*params, nqs, hold, np.asarray(ctx.gravity, float),
                  np.zeros(work_size.py_func(6 * nnode, nqm)))
        dofs = np.array([ctx.local_dofs(list(ln), 0, 0) for ln in lnodes], np.int64)
        g = make_group(self.name, specs, flexible_body_kernel, params, lnodes, dofs, OUTPUTS,
                       dissipative=True)
        g.naux = 1 + nqm
        g.extra["parts"] = [s.part for s in specs]
        g.extra["mounts"] = mounts
        g.extra["q_column"] = 1
        return g


register(FlexibleBodyFamily())
