"""A free steel rod spinning and vibrating (the ``beam_energy`` validation case of
:mod:`drivedyn.validation.beams`): its model, a start in its steady centrifugal stretch, its
lumped inertia, the kinetic energy of its rigid motion, and the energy a generalized-alpha
step leaves in an undamped oscillator."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.beams import STEEL, SolidCircular
from drivedyn.model import Spec, compile_model
from drivedyn.model.beams import add_straight_beam
from drivedyn.solver import GeneralizedAlpha

ROD_D = 0.02  # [m] diameter of the free rod of ``beam_energy``
ROD_OUTPUTS = ["energy.*", "rod.n*.position", "rod.n*.rotation", "rod.n*.velocity",
               "rod.n*.angular_velocity"]


def free_beam(n: int = 10, spin: float = 50.0) -> tuple[Spec, list[str]]:
    """A free steel rod (1 m along x from the origin, d = 20 mm, ``n`` elements, lumped
    mass) spinning rigidly about z through the origin at ``spin`` [rad/s]."""
    spec = Spec()
    nodes = add_straight_beam(spec, "rod", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), n,
                              SolidCircular(ROD_D), STEEL, angular_velocity=(0.0, 0.0, spin))
    return spec, nodes


def rod_inertia(n: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Lumped inertia of :func:`free_beam`'s nodes: masses (n+1,) [kg], section rotary
    inertias (n+1, 3, 3) [kg m^2] in the node frames (half an element's at each end of it)
    and the axial stiffness EA [N]."""
    p = SolidCircular(ROD_D).properties(STEEL)
    w = np.full(n + 1, 1.0 / n)
    w[[0, -1]] *= 0.5
    return p.mass_per_length * w, w[:, None, None] * np.diag(p.rotary_inertia), p.stiffness[0]


def rigid_kinetic_energy(x, R, v, w, m, J) -> tuple[float, np.ndarray, np.ndarray]:
    """Kinetic energy [J] of the rigid motion that has the momentum and angular momentum of
    lumped nodes (positions ``x`` (k, 3) [m], rotations ``R`` (k, 3, 3), velocities ``v``
    (k, 3) [m/s] and angular velocities ``w`` (k, 3) [rad/s], global; masses ``m`` (k,)
    [kg], rotary inertias ``J`` (k, 3, 3) [kg m^2] in the node frames): ``p^2 / (2 M) +
    L_c . I_c^-1 L_c / 2``, ``I_c`` the inertia of the current positions about the centre
    of mass. It is the least kinetic energy those momenta allow, so the kinetic energy in
    excess of it is that of the motion relative to the rigid motion. Also returns ``L_c``
    [kg m^2/s] and ``I_c`` [kg m^2]."""
    M = m.sum()
    r = x - (m[:, None] * x).sum(0) / M
    p = (m[:, None] * v).sum(0)
    Jg = np.einsum("kij,kjl,kml->kim", R, J, R)
    L = (m[:, None] * np.cross(r, v)).sum(0) + np.einsum("kij,kj->i", Jg, w)
    I = (np.einsum("k,kj,kj->", m, r, r) * np.eye(3) - np.einsum("k,ki,kj->ij", m, r, r)
         + Jg.sum(0))
    return float(p @ p / (2.0 * M) + 0.5 * L @ np.linalg.solve(I, L)), L, I


def spinning_kicked_rod(n: int, spin: float, kick: float):
    """:func:`free_beam` started in its steady centrifugal stretch (the lumped masses'
    discrete equilibrium: element tension = the centrifugal forces outboard of it, strain
    = tension / EA, centre of mass kept at x = 0.5 m) with the rigid velocities of the spin
    about the origin, plus a bending velocity ``kick sin(pi x / L)`` [m/s] along z. Returns
    the model, the initial state, the node indices and the kick (nd,) [m/s]."""
    spec, nodes = free_beam(n, spin)
    model = compile_model(spec)
    st = model.initial_state()
    idx = np.array([model.node_index[nm] for nm in nodes])
    m, _, EA = rod_inertia(n)
    x = st.x[idx, 0].copy()
    for _ in range(3):  # the strain (1e-5) hardly moves the masses: 3 passes converge
        f = m * spin**2 * (x - (m * x).sum() / m.sum())
        tension = np.cumsum(f[::-1])[::-1][1:]  # element e carries the nodes beyond it
        x = np.concatenate([[0.0], np.cumsum((1.0 + tension / EA) / n)])
        x += 0.5 - (m * x).sum() / m.sum()
    st.x[idx, 0] = x
    kick_v = np.zeros(model.nd)
    v = st.v.reshape(-1, 6)
    for k, i in enumerate(idx):
        v[i, :3] = np.cross((0.0, 0.0, spin), st.x[i])
        kick_v[6 * i + 2] = kick * np.sin(np.pi * k / n)
    st.v += kick_v
    return model, st, idx, kick_v


def generalized_alpha_energy_ratio(omega: float, h: float, steps: int, rho_inf: float) -> float:
    """Energy after ``steps`` steps over the initial energy of an undamped oscillator of
    circular frequency ``omega`` [rad/s] started with a velocity at its rest position,
    integrated by generalized-alpha in the solver's form (Arnold & Bruls 2007: pseudo-
    accelerations ``a``, ``(1 - am) a1 + am a0 = (1 - af) xdd1 + af xdd0``, the equation
    of motion ``xdd = -omega^2 x`` at each step's end)."""
    am, af, g, b = GeneralizedAlpha(rho_inf).coefficients
    # A z1 = B z0 for z = (x, v, xdd, a)
    A = np.array([[1.0, 0.0, 0.0, -h * h * b], [0.0, 1.0, 0.0, -h * g],
                  [omega**2, 0.0, 1.0, 0.0], [0.0, 0.0, -(1.0 - af), 1.0 - am]])
    B = np.array([[1.0, h, 0.0, h * h * (0.5 - b)], [0.0, 1.0, 0.0, h * (1.0 - g)],
                  [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, af, -am]])
    z = np.linalg.matrix_power(np.linalg.solve(A, B), steps) @ np.array([0.0, 1.0, 0.0, 0.0])
    return float(z[1] ** 2 + (omega * z[0]) ** 2)


def rod_state(ds, nodes: list[str], k: int) -> tuple[np.ndarray, ...]:
    """Positions, rotations, velocities, angular velocities (global) of ``nodes`` at
    output ``k`` of a run recorded with :data:`ROD_OUTPUTS`."""
    return tuple(np.stack([ds[f"{nm}.{q}"].values[k] for nm in nodes])
                 for q in ("position", "rotation", "velocity", "angular_velocity"))
