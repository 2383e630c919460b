"""Andrews' squeezing mechanism ("seven body mechanism"): a planar closed-loop benchmark.

Seven rigid bodies, about 7 cm across, in three closed loops through one point E, driven by a
constant motor torque on the crank and loaded by a spring; no gravity. It is the classic test
of integrators for index-3 multibody equations.

Sources:
    * E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer
      1996, sec. VII.7 ("Multibody systems"), after W. Schiehlen (ed.), *Multibody Systems
      Handbook*, Springer 1990 (M. Giles / P. Manning, "Andrews' squeezing mechanism").
    * F. Mazzia, F. Iavernaro, C. Magherini, *Test Set for IVP Solvers*, problem "andrews"
      (University of Bari, https://archimede.uniba.it/~testset/), release 2.4: the data, the
      consistent initial values and the reference solution at t = 0.03 s (computed with
      PSIDE at rtol = atol = 1e-14), quoted in :data:`TESTSET_Q_END`.

The state of the literature's formulation is the seven angles
``q = (beta, theta, gamma, phi, delta, omega, epsilon)``: crank angle ``beta`` (body 1 about
O), ``theta`` (body 2 relative to body 1 at F), ``gamma`` (body 3 about B), ``phi`` (body 4
relative to body 5 at G), ``delta`` (body 5 about A), ``omega`` (body 6 relative to body 7
at H), ``epsilon`` (body 7 about A); the six constraints close the loops O-F-E-B, O-F-E-G-A
and O-F-E-H-A.

:func:`squeezer_model` builds the mechanism in drivedyn from rigid bodies and joints;
:func:`reference_solution` integrates the seven-angle equations (index-1 form) with scipy,
an independent reference; :func:`squeezer_angles` reads ``(beta, theta)`` from a run.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from drivedyn.elements import Hinge, Spherical, SpringDamper, Torque, Universal
from drivedyn.model import Model, Spec, compile_model
from drivedyn.validation.common import rot_z

# masses [kg] and moments of inertia about the centres of mass [kg m^2] of bodies 1..7
MASS = (0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498)
INERTIA = (2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5)
# fixed points A, B (bearings) and C (spring anchor) [m]; the crank bearing O is the origin
XA, YA = -0.06934, -0.00227
XB, YB = -0.03635, 0.03273
XC, YC = 0.014, 0.072
# lengths [m]
D, DA, E, EA = 28e-3, 115e-4, 2e-2, 1421e-5
RR, RA = 7e-3, 92e-5
SS, SA, SB, SC, SD = 35e-3, 1874e-5, 1043e-5, 18e-3, 2e-2
TA, TB = 2308e-5, 916e-5
U, UA, UB = 4e-2, 1228e-5, 449e-5
ZF, ZT, FA = 2e-2, 4e-2, 1421e-5
MOM = 0.033      # motor torque on the crank [N m]
C0 = 4530.0      # spring stiffness [N/m]
L0 = 0.07785     # spring free length [m]
T_END = 0.03     # [s]

# consistent initial angles (beta, theta, gamma, phi, delta, omega, epsilon) [rad], at rest
Q0 = np.array([-0.0617138900142764496358948458001, 0.0,
               0.455279819163070380255912382449, 0.222668390165885884674473185609,
               0.487364979543842550225598953530, -0.222668390165885884674473185609,
               1.23054744454982119249735015568])
# initial accelerations of beta and theta [rad/s^2] and the first two multipliers (the others
# are zero), from the test set
QDD0 = (14222.4439199541138705911625887, -10666.8329399655854029433719415)
LAM0 = (98.5668703962410896057654982170, -6.12268834425566265503114393122)
# the test set's reference angles at t = 0.03 s [rad]
TESTSET_Q_END = np.array([0.1581077119629904e2, -0.1575637105984298e2,
                          0.4082224013073101e-1, -0.5347301163226948,
                          0.5244099658805304, 0.5347301163226948,
                          0.1048080741042263e1])

# ---------------------------------------------------------------------------------------------
# the seven-angle formulation
# ---------------------------------------------------------------------------------------------
# Positions are sums of terms c * (cos(a.q), sin(a.q)) rotated by a quarter turn k times
# (k = 0: (cos, sin), 1: (-sin, cos), 2: -(cos, sin), 3: (sin, -cos)) plus a constant, with
# integer vectors a: their derivatives in q and the velocity terms follow from the terms.
_BETA, _THETA, _GAMMA, _PHI, _DELTA, _OMEGA, _EPS = np.eye(7)


def _point(const: tuple[float, float], *terms: tuple[float, int, np.ndarray]) -> tuple:
    return (np.array(const, float), tuple((c, k, a) for c, k, a in terms))


def _eval(point: tuple, q: np.ndarray, qd: np.ndarray) -> tuple:
    """Position (2,), Jacobian (2, 7) and ``dJ/dt qd`` (2,) of a point."""
    const, terms = point
    p = const.copy()
    J = np.zeros((2, 7))
    Jdqd = np.zeros(2)
    for c, k, a in terms:
        x = float(a @ q)
        w = float(a @ qd)
        u = np.array([np.cos(x), np.sin(x)])       # the direction
        du = np.array([-np.sin(x), np.cos(x)])     # its derivative in x
        rot = np.linalg.matrix_power(np.array([[0.0, -1.0], [1.0, 0.0]]), k)
        p += c * rot @ u
        J += c * np.outer(rot @ du, a)
        Jdqd -= c * w * w * rot @ u
    return p, J, Jdqd


_F = (RR, 0, _BETA)                  # crank pin F from O
_EF = (D, 2, _BETA + _THETA)         # E from F (body 2)
# E reached through each loop (the constraints: the three agree with the first)
_E_LOOPS = (
    _point((0.0, 0.0), _F, _EF),
    _point((XB, YB), (SS, 3, _GAMMA)),
    _point((XA, YA), (ZT, 0, _DELTA), (E, 3, _PHI + _DELTA)),
    _point((XA, YA), (U, 3, _EPS), (ZF, 0, _OMEGA + _EPS)),
)
# centres of mass and absolute angles of bodies 1..7
_COM = (
    _point((0.0, 0.0), (RA, 0, _BETA)),
    _point((0.0, 0.0), _F, (DA, 2, _BETA + _THETA)),
    _point((XB, YB), (SA, 3, _GAMMA), (SB, 0, _GAMMA)),
    _point((XA, YA), (ZT, 0, _DELTA), (E - EA, 3, _PHI + _DELTA)),
    _point((XA, YA), (TA, 0, _DELTA), (TB, 1, _DELTA)),
    _point((XA, YA), (U, 3, _EPS), (ZF - FA, 0, _OMEGA + _EPS)),
    _point((XA, YA), (UA, 3, _EPS), (UB, 0, _EPS)),
)
_ANGLE = (_BETA, _BETA + _THETA, _GAMMA, _PHI + _DELTA, _DELTA, _OMEGA + _EPS, _EPS)
_SPRING_D = _point((XB, YB), (SD, 0, _GAMMA), (SC, 3, _GAMMA))


def equations(q: np.ndarray, qd: np.ndarray) -> tuple:
    """The seven-angle equations at ``(q, qd)``: mass matrix M (7, 7), forces f (7,)
    (applied and velocity terms), constraints g (6,), their Jacobian G (6, 7) and
    ``dG/dt qd`` (6,); the motion is ``M qdd = f - G^T lam``, ``g = 0``."""
    M = np.zeros((7, 7))
    f = np.zeros(7)
    for m, i, point, a in zip(MASS, INERTIA, _COM, _ANGLE, strict=True):
        _, J, Jdqd = _eval(point, q, qd)
        M += m * J.T @ J + i * np.outer(a, a)
        f -= m * J.T @ Jdqd
    f[0] += MOM
    pd, JD, _ = _eval(_SPRING_D, q, qd)
    dist = pd - np.array([XC, YC])
    length = float(np.hypot(*dist))
    f += JD.T @ (-C0 * (length - L0) / length * dist)
    e0, J0, c0 = _eval(_E_LOOPS[0], q, qd)
    g = np.zeros(6)
    G = np.zeros((6, 7))
    gam = np.zeros(6)
    for k, loop in enumerate(_E_LOOPS[1:]):
        ek, Jk, ck = _eval(loop, q, qd)
        g[2 * k:2 * k + 2] = e0 - ek
        G[2 * k:2 * k + 2] = J0 - Jk
        gam[2 * k:2 * k + 2] = c0 - ck
    return M, f, g, G, gam


def accelerations(q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(qdd, lam)`` of the index-1 form ``[M G^T; G 0] [qdd; lam] = [f; -dG/dt qd]``."""
    M, f, _, G, gam = equations(q, qd)
    A = np.zeros((13, 13))
    A[:7, :7] = M
    A[:7, 7:] = G.T
    A[7:, :7] = G
    x = np.linalg.solve(A, np.concatenate([f, -gam]))
    return x[:7], x[7:]


def _project(q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Newton projection of ``q`` onto ``g = 0`` and of ``qd`` onto ``G qd = 0`` (least
    change, Euclidean)."""
    for _ in range(5):
        _, _, g, G, _ = equations(q, qd)
        q = q - G.T @ np.linalg.solve(G @ G.T, g)
    _, _, _, G, _ = equations(q, qd)
    qd = qd - G.T @ np.linalg.solve(G @ G.T, G @ qd)
    return q, qd


@functools.cache
def reference_solution(t_end: float = T_END, rtol: float = 1e-12,
                       atol: float = 1e-14) -> tuple[np.ndarray, np.ndarray]:
    """The angles ``q`` and their rates at ``t_end`` [s] from the seven-angle equations in
    index-1 form, integrated by scipy's DOP853 at ``rtol``/``atol`` and projected onto the
    position and velocity constraints at the end (the drift of the index-1 form at these
    tolerances is below 1e-12 rad). Agrees with :data:`TESTSET_Q_END` to 2e-9 rad, 1e-10 of
    the crank angle, a difference that stays at tighter tolerances
    (``tests/verification/test_squeezer.py``)."""
    from scipy.integrate import solve_ivp

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        qdd, _ = accelerations(y[:7], y[7:])
        return np.concatenate([y[7:], qdd])

    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([Q0, np.zeros(7)]), method="DOP853",
                    rtol=rtol, atol=atol)
    if not sol.success:
        raise RuntimeError(f"squeezer reference: {sol.message}")
    return _project(sol.y[:7, -1], sol.y[7:, -1])


# ---------------------------------------------------------------------------------------------
# the drivedyn model
# ---------------------------------------------------------------------------------------------

def _global(origin: np.ndarray, angle: float, local: tuple[float, float]) -> np.ndarray:
    """Global position (3,) of the in-plane ``local`` point of a body frame at ``origin``
    turned by ``angle``."""
    p = rot_z(angle) @ np.array([local[0], local[1], 0.0])
    return np.array([origin[0], origin[1], 0.0]) + p


# a marker whose y axis is the body's local x (its x along the global z): the second cross
# axis of a universal joint, in the plane and across the body's line to E
_UY_ALONG_X = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
# the same with the y axis along the body's local y
_UY_ALONG_Y = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


def squeezer_model(joints: str = "mixed", scale: float = 1.0) -> Model:
    """Andrews' squeezer from seven rigid bodies in the x-y plane, at rest in the consistent
    initial position :data:`Q0`.

    Body frames: body 1 at O, body 2 at F, body 3 at B, body 4 at G, body 5 and body 7 at A,
    body 6 at H, each turned about z by its absolute angle; the centres of mass, the points
    of the joints and the spring's point D are the literature's local coordinates. A
    constant torque :data:`MOM` on body 1; a spring of stiffness :data:`C0` and free length
    :data:`L0` from D on body 3 to the fixed point C.

    ``scale``: every length times ``scale``, the moments of inertia and the motor torque
    times ``scale``^2 (masses and the spring's stiffness unchanged): a dynamically similar
    mechanism whose angles follow the same reference (the seven-angle equations scale by
    ``scale``^2 throughout). The engine must converge it alike at any scale.

    ``joints``:
        ``"mixed"`` (default): non-redundant, 41 constraint rows for 42 dofs (one dof). The
        spanning tree O (ground-1), F (1-2), A (ground-5), A (ground-7) is hinges; each loop
        closes at E with a spherical joint to body 2 and takes a universal joint (axes z and
        the in-plane direction across the body's line to E) at B (ground-3), G (5-4) and H
        (7-6). The universals' second axes and the sphericals' z rows together hold each
        loop in the plane.
        ``"hinges"``: a planar hinge at each of the ten joints (50 rows, 9 of them
        redundant: three per loop), the mechanism as drawn; the solver sets the 9 dependent
        rows aside (:mod:`drivedyn.solver.redundancy`).
    """
    if joints not in ("mixed", "hinges"):
        raise ValueError(f"squeezer_model: joints must be 'mixed' or 'hinges', got {joints!r}")
    k = float(scale)
    if not (np.isfinite(k) and k > 0.0):
        raise ValueError(f"squeezer_model: scale must be > 0, got {scale!r}")
    beta, theta, gamma, phi, delta, omega, eps = Q0
    O = np.zeros(3)
    A = k * np.array([XA, YA, 0.0])
    B = k * np.array([XB, YB, 0.0])
    F = _global(O, beta, (k * RR, 0.0))
    G = _global(A, delta, (k * ZT, 0.0))
    H = _global(A, eps, (0.0, -k * U))
    # (name, mass, inertia, origin, angle, local centre of mass)
    bodies = (
        ("b1", 0, O, beta, (RA, 0.0)),
        ("b2", 1, F, beta + theta, (-DA, 0.0)),
        ("b3", 2, B, gamma, (SB, -SA)),
        ("b4", 3, G, phi + delta, (0.0, -(E - EA))),
        ("b5", 4, A, delta, (TA, TB)),
        ("b6", 5, H, omega + eps, (ZF - FA, 0.0)),
        ("b7", 6, A, eps, (UB, -UA)),
    )
    spec = Spec(gravity=(0.0, 0.0, 0.0))
    for name, ib, origin, angle, com in bodies:
        i = INERTIA[ib] * k * k
        spec.add_rigid_body(name, MASS[ib], [0.6 * i, 0.6 * i, i],
                            com=(k * com[0], k * com[1], 0.0), position=origin,
                            rotation=rot_z(angle))
    z = (0.0, 0.0, 1.0)

    def marker(name: str, body: str, local: tuple[float, float], rotation: Any = None) -> str:
        pos = (k * local[0], k * local[1], 0.0)
        if rotation is None:
            return spec.add_marker(name, body, position=pos, axis=z)
        return spec.add_marker(name, body, position=pos, rotation=rotation)

    def ground(name: str, p: np.ndarray, rotation: Any = None) -> str:
        return marker(name, "ground", (float(p[0]) / k, float(p[1]) / k), rotation)

    hinges = joints == "hinges"
    ux = None if hinges else _UY_ALONG_X
    uy = None if hinges else _UY_ALONG_Y
    # the parent side of a universal joint: its x (the first cross axis) along the global z
    cross = None if hinges else _UY_ALONG_X
    closing = Hinge if hinges else Spherical
    bearing3 = Hinge if hinges else Universal
    spec.add(Hinge("O", ground("O_ground", O), marker("O_b1", "b1", (0.0, 0.0))))
    spec.add(Hinge("F", marker("F_b1", "b1", (RR, 0.0)), marker("F_b2", "b2", (0.0, 0.0))))
    spec.add(Hinge("A5", ground("A5_ground", A), marker("A5_b5", "b5", (0.0, 0.0))))
    spec.add(Hinge("A7", ground("A7_ground", A), marker("A7_b7", "b7", (0.0, 0.0))))
    spec.add(bearing3("B", ground("B_ground", B, cross),
                      marker("B_b3", "b3", (0.0, 0.0), ux)))
    spec.add(bearing3("G", marker("G_b5", "b5", (ZT, 0.0), cross),
                      marker("G_b4", "b4", (0.0, 0.0), ux)))
    spec.add(bearing3("H", marker("H_b7", "b7", (0.0, -U), cross),
                      marker("H_b6", "b6", (0.0, 0.0), uy)))
    spec.add(closing("E3", marker("E_b2_3", "b2", (-D, 0.0)), marker("E_b3", "b3", (0.0, -SS))))
    spec.add(closing("E4", marker("E_b2_4", "b2", (-D, 0.0)), marker("E_b4", "b4", (0.0, -E))))
    spec.add(closing("E6", marker("E_b2_6", "b2", (-D, 0.0)), marker("E_b6", "b6", (ZF, 0.0))))
    spec.add(Torque("motor", marker("motor", "b1", (0.0, 0.0)), vector=(0.0, 0.0, MOM * k * k)))
    spec.add(SpringDamper("spring", marker("D_b3", "b3", (SD, -SC)),
                          ground("C_ground", k * np.array([XC, YC])), stiffness=C0,
                          free_length=k * L0))
    return compile_model(spec)


def squeezer_angles(res: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(beta, theta)`` [rad] at the output times of a run of :func:`squeezer_model`: the
    crank's angle (unwrapped from body 1's orientation, so it counts turns; the outputs must
    be closer than half a turn) and body 2's angle relative to body 1, comparable with the
    first two components of :func:`reference_solution` and :data:`TESTSET_Q_END`."""
    R1 = res["b1.rotation"].values if "b1.rotation" in res else None
    if R1 is None:
        raise KeyError("squeezer_angles: the run holds no 'b1.rotation'")
    R2 = res["b2.rotation"].values
    a1 = np.unwrap(np.arctan2(R1[:, 1, 0], R1[:, 0, 0]))
    a2 = np.unwrap(np.arctan2(R2[:, 1, 0], R2[:, 0, 0]))
    a1 += Q0[0] - a1[0]
    a2 += Q0[0] + Q0[1] - a2[0]
    return a1, a2 - a1
