"""The validation cases (registered with :func:`drivedyn.validation.base.register_case`).

Every case builds small mechanisms, simulates them and compares what comes out with an exact
(closed-form or quadrature) reference, reporting one :class:`CaseResult` per checked quantity.
``quick=True`` runs a shorter / coarser variant (used by the test suite); tolerances are
derived from the step size actually used, so both variants are checked honestly.

The exact references are plain functions of this module (``euler_free_body_exact``,
``top_nutation_reference``, ``pendulum_angle_exact``, ...) so that the tests can check them
independently of the simulator.

Notes on integrator settings (see the report of the validation work):

* ``rho_inf = 1`` (no numerical damping, the trapezoidal rule) is used where energy
  conservation itself is checked. With index-3 constraints that carry large reactions (heavy
  top, large-amplitude pendulum) the undamped scheme shows the classical growing ``(-1)^n``
  oscillation of the multipliers after a few seconds, so the long constrained runs use
  ``rho_inf = 0.9`` (still second order, negligible damping of the physical motion).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy.integrate import quad
from scipy.special import ellipj, ellipk, ellipkinc

import drivedyn as dd
from drivedyn.rotations import frame_from_axis, rotation_from_euler_zxz
from drivedyn.validation.base import CaseResult, compare, register_case

G = 9.81  # [m/s^2] gravitational acceleration used by all cases


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------


def _rz(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _ry(a: float) -> np.ndarray:
    """Rotation about y by ``a``: maps x to (cos a, 0, -sin a)."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def crossings(t: np.ndarray, y: np.ndarray, direction: int = 0) -> np.ndarray:
    """Times where ``y`` crosses zero, linearly interpolated between samples.

    ``direction`` +1: upward only, -1: downward only, 0: both.
    """
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    up = (y[:-1] < 0.0) & (y[1:] >= 0.0)
    down = (y[:-1] > 0.0) & (y[1:] <= 0.0)
    sel = up if direction > 0 else down if direction < 0 else (up | down)
    i = np.nonzero(sel)[0]
    return t[i] + (t[i + 1] - t[i]) * y[i] / (y[i] - y[i + 1])


def _peak(t: np.ndarray, y: np.ndarray) -> float:
    """Largest value of a sampled smooth signal, refined by a parabola through the three
    samples around the largest sample."""
    i = int(np.argmax(y))
    if i == 0 or i == len(y) - 1:
        return float(y[i])
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = y0 - 2.0 * y1 + y2
    if den >= 0.0:
        return float(y1)
    return float(y1 - 0.125 * (y2 - y0) ** 2 / den)


def _failed(case: str, quantity: str, unit: str, tol: float, source: str,
            res: Any) -> CaseResult:
    """A failed check for a run that did not reach its end time."""
    r = CaseResult(case, quantity, np.nan, np.nan, unit, np.inf, tol,
                   f"{source}; RUN FAILED: {getattr(res, 'message', res)}")
    return r


def _figure(figure_dir: str | None, name: str, draw: Callable[[Any], None]) -> list[str]:
    """Draw a figure with ``draw(fig)`` and save it as ``figure_dir/name.png`` (Agg canvas,
    no pyplot state: safe in tests and without a display)."""
    if not figure_dir:
        return []
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    os.makedirs(figure_dir, exist_ok=True)
    fig = Figure(figsize=(8, 5))
    FigureCanvasAgg(fig)
    draw(fig)
    fig.tight_layout()
    path = os.path.join(figure_dir, f"{name}.png")
    fig.savefig(path, dpi=110)
    return [path]


def _finish(results: list[CaseResult], t0: float, figures: list[str]) -> list[CaseResult]:
    wall = time.perf_counter() - t0
    for r in results:
        r.wall_s = wall
        r.figures = list(figures)
    return results


# ---------------------------------------------------------------------------------------------
# exact references
# ---------------------------------------------------------------------------------------------


def euler_free_body_exact(J: Sequence[float], w0: Sequence[float], t: Any) -> np.ndarray:
    """Body-frame angular velocity (..., 3) of a torque-free rigid body (Euler-Poinsot).

    ``J`` principal moments with ``J1 < J2 < J3``; ``w0`` initial body angular velocity, in
    the regime ``|H|^2 > 2 T J2`` (rotation around the axis of the largest moment).
    Landau & Lifshitz, Mechanics, section 37: ``Omega = (A1 cn, A2 sn, A3 dn)(tau)`` with
    ``tau = rate t + tau0``, parameter ``m = (J2 - J1)(2 T J3 - H^2) / ((J3 - J2)(H^2 - 2 T J1))``.
    """
    J1, J2, J3 = (float(v) for v in J)
    w = np.asarray(w0, float)
    Jv = np.array([J1, J2, J3])
    H2 = float(np.sum((Jv * w) ** 2))
    E2 = float(np.sum(Jv * w * w))
    if not (J1 < J2 < J3) or not H2 > E2 * J2:
        raise ValueError("euler_free_body_exact needs J1 < J2 < J3 and |H|^2 > 2 T J2")
    A1 = np.sqrt((E2 * J3 - H2) / (J1 * (J3 - J1)))
    A2 = np.sqrt((E2 * J3 - H2) / (J2 * (J3 - J2)))
    s = 1.0 if w[2] >= 0.0 else -1.0
    A3 = s * np.sqrt((H2 - E2 * J1) / (J3 * (J3 - J1)))
    rate = np.sqrt((J3 - J2) * (H2 - E2 * J1) / (J1 * J2 * J3))
    m = (J2 - J1) * (E2 * J3 - H2) / ((J3 - J2) * (H2 - E2 * J1))
    tau0 = ellipkinc(np.arctan2(w[1] / A2, w[0] / A1), m)
    sn, cn, dn, _ = ellipj(s * rate * np.asarray(t, float) + tau0, m)
    return np.stack([A1 * cn, A2 * sn, A3 * dn], axis=-1)


def top_steady_precession_rate(I1: float, I3: float, m: float, g: float, l: float,
                               theta: float, w3: float, branch: str = "slow") -> float:
    """Precession rate [rad/s] of a heavy symmetric top in steady precession.

    ``I1`` transverse moment about the fixed point, ``I3`` axial moment, ``l`` fixed point to
    centre of mass, ``theta`` nutation angle from the upward vertical, ``w3`` spin component
    along the symmetry axis (``psidot + phidot cos theta``). Root of
    ``m g l = Omega (I3 w3 - I1 Omega cos theta)`` (the theta equation of the Lagrangian
    ``L = I1/2 (thetadot^2 + phidot^2 sin^2) + I3/2 w3^2 - m g l cos theta`` with
    ``thetadot = thetaddot = 0``).
    """
    c = np.cos(theta)
    p = I3 * w3
    disc = p * p - 4.0 * I1 * c * m * g * l
    if disc < 0.0:
        raise ValueError("no steady precession at this spin (spin too slow)")
    # numerically stable roots of I1 c W^2 - p W + m g l = 0
    q = 0.5 * (p + np.copysign(np.sqrt(disc), p))
    slow = m * g * l / q
    fast = q / (I1 * c)
    return float(slow if branch == "slow" else fast)


def top_nutation_reference(I1: float, I3: float, m: float, g: float, l: float,
                           theta0: float, w3: float, phidot0: float = 0.0) -> dict[str, float]:
    """Nutation of a heavy symmetric top released with ``thetadot = 0`` (Goldstein, Classical
    Mechanics, section 5.7): with ``u = cos theta``,
    ``udot^2 = f(u) = (1 - u^2)(alpha - beta u) - (b - a u)^2``,
    ``phidot = (b - a u) / (1 - u^2)``, ``a = I3 w3 / I1``, ``b = (I1 phidot0 sin^2 theta0 +
    I3 w3 u0) / I1``, ``beta = 2 m g l / I1``, ``alpha = phidot0^2 sin^2 theta0 + beta u0``.

    The motion is between the two roots ``u1 < u2`` of the cubic in [-1, 1]. Quadratures over
    one nutation period (substitution ``u = u1 + (u2 - u1) sin^2 s`` removes the endpoint
    square-root singularities)::

        T_nut = 2 int du / sqrt(f),   dphi = 2 int (b - a u)/(1 - u^2) du / sqrt(f)

    Returns ``T_nut`` [s], ``dphi`` [rad], ``theta_min``, ``theta_max`` [rad], the roots
    ``u1, u2, u3`` and the closed form ``T_nut_elliptic = 4 K(k^2) / sqrt(beta (u3 - u1))``.
    """
    u0 = np.cos(theta0)
    s0 = np.sin(theta0)
    a = I3 * w3 / I1
    b = (I1 * phidot0 * s0 * s0 + I3 * w3 * u0) / I1
    beta = 2.0 * m * g * l / I1
    alpha = phidot0 ** 2 * s0 * s0 + beta * u0
    coeffs = [beta, -alpha - a * a, -beta + 2.0 * a * b, alpha - b * b]
    roots = np.sort(np.real(np.roots(coeffs)))
    # polish the roots (Newton on the cubic)
    for _ in range(3):
        f = np.polyval(coeffs, roots)
        df = np.polyval(np.polyder(coeffs), roots)
        roots = roots - np.where(df != 0.0, f / np.where(df != 0.0, df, 1.0), 0.0)
    u1, u2, u3 = (float(r) for r in roots)
    du = u2 - u1

    def u_of(s: float) -> float:
        return u1 + du * np.sin(s) ** 2

    # f = beta (u - u1)(u2 - u)(u3 - u): du / sqrt(f) = 2 ds / sqrt(beta (u3 - u))
    def w_t(s: float) -> float:
        return 2.0 / np.sqrt(beta * (u3 - u_of(s)))

    def w_phi(s: float) -> float:
        u = u_of(s)
        return (b - a * u) / (1.0 - u * u) * w_t(s)

    opts = {"epsabs": 0.0, "epsrel": 1e-13, "limit": 200}
    T = 2.0 * quad(w_t, 0.0, 0.5 * np.pi, **opts)[0]
    dphi = 2.0 * quad(w_phi, 0.0, 0.5 * np.pi, **opts)[0]
    kk = du / (u3 - u1)
    T_ell = 4.0 * ellipk(kk) / np.sqrt(beta * (u3 - u1))
    return {"T_nut": T, "dphi": dphi, "theta_min": float(np.arccos(min(u2, 1.0))),
            "theta_max": float(np.arccos(max(u1, -1.0))), "u1": u1, "u2": u2, "u3": u3,
            "T_nut_elliptic": float(T_ell), "a": a, "b": b, "alpha": alpha, "beta": beta}


def pendulum_period_exact(I_o: float, m: float, g: float, d: float, theta0: float) -> float:
    """Period [s] of a physical pendulum released from rest at ``theta0`` [rad]:
    ``4 sqrt(I_o / (m g d)) K(k^2)``, ``k = sin(theta0 / 2)`` (scipy's ``ellipk`` takes
    ``m = k^2``)."""
    return float(4.0 * np.sqrt(I_o / (m * g * d)) * ellipk(np.sin(0.5 * theta0) ** 2))


def pendulum_angle_exact(I_o: float, m: float, g: float, d: float, theta0: float,
                         t: Any) -> np.ndarray:
    """Angle [rad] of a physical pendulum released from rest at ``theta0`` at t = 0:
    ``sin(theta/2) = k sn(K - omega0 t, k)``, ``k = sin(theta0/2)``,
    ``omega0 = sqrt(m g d / I_o)``."""
    k = np.sin(0.5 * theta0)
    K = ellipk(k * k)
    w0 = np.sqrt(m * g * d / I_o)
    sn = ellipj(K - w0 * np.asarray(t, float), k * k)[0]
    return 2.0 * np.arcsin(k * sn)


def slider_crank_position(r: float, l: float, theta: Any) -> np.ndarray:
    """Piston position [m] along the line of stroke through the crank centre:
    ``x = r cos theta + sqrt(l^2 - r^2 sin^2 theta)``."""
    th = np.asarray(theta, float)
    return r * np.cos(th) + np.sqrt(l * l - (r * np.sin(th)) ** 2)


def slider_crank_statics(r: float, l: float, P: float, theta: float) -> tuple[float, float]:
    """Crank torque and guide normal force of a slider-crank in static equilibrium with a
    force ``P`` pushing the piston towards the crank (no gravity, no friction):
    ``T = P r sin(theta + phi) / cos(phi)`` (the torque the gas force exerts on the crank,
    positive in the direction of increasing theta), ``N = P tan(phi)``,
    ``sin(phi) = r sin(theta) / l``."""
    phi = np.arcsin(r * np.sin(theta) / l)
    return float(P * r * np.sin(theta + phi) / np.cos(phi)), float(P * np.tan(phi))


# ---------------------------------------------------------------------------------------------
# model builders
# ---------------------------------------------------------------------------------------------

# physical pendulum: a rod whose centre of mass is d = 1 m from the pivot
PEND_M = 1.0
PEND_D = 1.0
PEND_J = np.diag([1e-4, 1e-2, 1e-2])  # about the centre of mass, body frame (x along the rod)
PEND_IO = PEND_J[1, 1] + PEND_M * PEND_D ** 2  # about the pivot


def pendulum_model(theta0: float, damper: tuple[float, float] | None = None) -> dd.Model:
    """Physical pendulum swinging in the x-z plane about the global y axis.

    ``theta`` is measured from the downward vertical towards +x (hinge axis -y, so the hinge
    angle output is ``theta - theta0``). ``damper``: optional (stiffness, damping) of a torsional
    spring-damper in parallel with the hinge (free angle = the initial angle).
    """
    Rb = _ry(0.5 * np.pi - theta0)  # body x (the rod) points at angle theta0 from -z
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("rod", PEND_M, PEND_J, com=(PEND_D, 0.0, 0.0), rotation=Rb)
    spec.add_marker("pivot", "ground", axis=(0.0, -1.0, 0.0))
    spec.add_marker("rod_pivot", "rod", rotation=Rb.T @ frame_from_axis([0.0, -1.0, 0.0]))
    spec.add(dd.Hinge("hinge", "pivot", "rod_pivot"))
    if damper is not None:
        spec.add(dd.TorsionalSpringDamper("damper", "pivot", "rod_pivot",
                                          stiffness=damper[0], damping=damper[1]))
    return dd.compile_model(spec)


def _pendulum_angle(res: Any) -> np.ndarray:
    x = res["rod.position"].values
    return np.arctan2(x[:, 0], -x[:, 2])


# heavy symmetric top (fixed point at the origin, symmetry axis = body z)
TOP_M = 1.0
TOP_L = 0.05  # fixed point to centre of mass [m]
TOP_I1C = 1.5e-3  # transverse moment about the centre of mass [kg m^2]
TOP_I3 = 2.5e-3  # axial moment [kg m^2]
TOP_I1 = TOP_I1C + TOP_M * TOP_L ** 2  # transverse moment about the fixed point


def top_model(theta0: float, w3: float, phidot0: float) -> dd.Model:
    """Heavy symmetric top on a spherical joint at the origin, symmetry axis tilted by
    ``theta0`` from +z (Euler z-x-z angles (0, theta0, 0)), spin component ``w3`` along the
    axis, precession rate ``phidot0`` about +z, ``thetadot = 0``."""
    R0 = rotation_from_euler_zxz(0.0, theta0, 0.0)
    k = R0[:, 2]
    psidot = w3 - phidot0 * np.cos(theta0)
    w = phidot0 * np.array([0.0, 0.0, 1.0]) + psidot * k
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("top", TOP_M, [TOP_I1C, TOP_I1C, TOP_I3], com=(0.0, 0.0, TOP_L),
                        rotation=R0, angular_velocity=w)
    spec.add_marker("fixed_point", "ground")
    spec.add_marker("top_tip", "top")
    spec.add(dd.Spherical("ball", "fixed_point", "top_tip"))
    return dd.compile_model(spec)


def _top_angles(res: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(theta, unwrapped phi, udot) of the top's symmetry axis k = R e3."""
    R = res["top.rotation"].values
    k = R[:, :, 2]
    w = res["top.angular_velocity"].values
    theta = np.arccos(np.clip(k[:, 2], -1.0, 1.0))
    phi = np.unwrap(np.arctan2(k[:, 0], -k[:, 1]))
    udot = np.cross(w, k)[:, 2]
    return theta, phi, udot


# slider-crank (in the x-y plane, crank centre at the origin, stroke along +x)
SC_R = 0.1
SC_L = 0.3


def slider_crank_model(theta: float, driver: tuple[str, Any] = ("speed", 2.0 * np.pi),
                       piston_force: float = 0.0, rod_com_offset: float = 0.0,
                       guide_spring: tuple[float, float] | None = None) -> dd.Model:
    """Slider-crank at crank angle ``theta``, driven by a :class:`JointDriver` on the main
    bearing (``driver = (quantity, function)``).

    Joints (non-redundant, 17 constraints for 3 bodies, 1 dof): main bearing hinge (ground -
    crank), spherical crank pin (crank - rod), universal piston pin (rod - slider; cross axes
    z and y), prismatic guide (ground - slider along x). Planar hinges everywhere would give
    3 redundant rows, which the solver rightly refuses (singular matrix).

    ``piston_force``: force P [N] on the piston towards the crank (-x). ``rod_com_offset``:
    lateral offset [m] of the rod's centre of mass from the pin line (does not change the
    statics). ``guide_spring``: (stiffness, damping) of a spring-damper from the slider to a
    ground point on the stroke line beyond the piston.
    """
    phi = np.arcsin(SC_R * np.sin(theta) / SC_L)
    A = SC_R * np.array([np.cos(theta), np.sin(theta), 0.0])
    B = np.array([float(slider_crank_position(SC_R, SC_L, theta)), 0.0, 0.0])
    Rr = _rz(-phi)  # rod body x from crank pin A to piston pin B
    spec = dd.Spec()
    spec.add_rigid_body("crank", 1.0, [1e-4, 1e-3, 1e-3], com=(SC_R / 2, 0.0, 0.0),
                        rotation=_rz(theta))
    spec.add_rigid_body("rod", 2.0, [1e-4, 2e-2, 2e-2], com=(SC_L / 2, rod_com_offset, 0.0),
                        position=A, rotation=Rr)
    spec.add_rigid_body("slider", 0.5, [1e-4, 1e-4, 1e-4], position=B)
    z = (0.0, 0.0, 1.0)
    spec.add_marker("main", "ground", axis=z)
    spec.add_marker("crank_main", "crank", axis=z)
    spec.add_marker("crank_pin", "crank", position=(SC_R, 0.0, 0.0))
    spec.add_marker("rod_big_end", "rod")
    # universal: x of the rod marker along global z, y of the slider marker along global y
    Ru = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    spec.add_marker("rod_small_end", "rod", position=(SC_L, 0.0, 0.0), rotation=Rr.T @ Ru)
    spec.add_marker("slider_pin", "slider")
    spec.add_marker("guide", "ground", axis=(1.0, 0.0, 0.0))
    spec.add_marker("slider_guide", "slider", axis=(1.0, 0.0, 0.0))
    spec.add(dd.Hinge("main_bearing", "main", "crank_main"))
    spec.add(dd.Spherical("crank_pin_joint", "crank_pin", "rod_big_end"))
    spec.add(dd.Universal("piston_pin", "rod_small_end", "slider_pin"))
    spec.add(dd.Prismatic("guide_joint", "guide", "slider_guide"))
    spec.add(dd.JointDriver("crank_drive", "main_bearing", driver[1], quantity=driver[0]))
    if piston_force:
        spec.add(dd.Force("gas", "slider_guide", vector=(-piston_force, 0.0, 0.0)))
    if guide_spring is not None:
        spec.add_marker("spring_anchor", "ground", position=(SC_R + SC_L + 0.2, 0.0, 0.0))
        spec.add(dd.SpringDamper("guide_spring", "spring_anchor", "slider_guide",
                                 stiffness=guide_spring[0], damping=guide_spring[1]))
    return dd.compile_model(spec)


SCREW_PITCH = 0.01  # [m/rev]
SCREW_M = 2.0
SCREW_J = (0.01, 0.01, 0.02)


def screw_model(speed: float, pitch: float = SCREW_PITCH) -> dd.Model:
    """A nut (axisymmetric about z) on a screw joint along +z, under gravity -z, turned by a
    speed driver at ``speed`` [rad/s] (initial velocities consistent with the screw)."""
    v = pitch * speed / (2.0 * np.pi)
    spec = dd.Spec(gravity=(0.0, 0.0, -G))
    spec.add_rigid_body("nut", SCREW_M, SCREW_J, velocity=(0.0, 0.0, v),
                        angular_velocity=(0.0, 0.0, speed))
    spec.add_marker("thread", "ground", axis=(0.0, 0.0, 1.0))
    spec.add_marker("nut_thread", "nut", axis=(0.0, 0.0, 1.0))
    spec.add(dd.Screw("screw", "thread", "nut_thread", pitch=pitch))
    spec.add(dd.JointDriver("turn", "screw", speed, quantity="speed"))
    return dd.compile_model(spec)


# ---------------------------------------------------------------------------------------------
# cases
# ---------------------------------------------------------------------------------------------

TF_J = np.array([1.0, 2.0, 3.0])
TF_W0 = np.array([0.2, 1.0, 0.3])  # body frame [rad/s], not along a principal axis


def torque_free_model(pinned: bool) -> dd.Model:
    """Asymmetric body spinning about a non-principal axis, centre of mass at the origin.

    ``pinned=False``: a free body, no gravity. ``pinned=True``: the same body held at its
    centre of mass by a spherical joint, under gravity (the weight and the reaction both act
    at the centre of mass, so the rotation is still torque-free).
    """
    spec = dd.Spec(gravity=(0.0, 0.0, -G) if pinned else (0.0, 0.0, 0.0))
    spec.add_rigid_body("body", 1.0, TF_J, angular_velocity=TF_W0)
    if pinned:
        spec.add_marker("origin", "ground")
        spec.add_marker("body_com", "body")
        spec.add(dd.Spherical("pin", "origin", "body_com"))
    return dd.compile_model(spec)


@register_case("torque_free_body")
def torque_free_body(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Torque-free asymmetric body (J = 1, 2, 3 kg m^2), rho_inf = 1: angular momentum and
    kinetic energy are invariants; the body angular velocity follows Euler-Poinsot."""
    t0 = time.perf_counter()
    case = "torque_free_body"
    h = 1e-2 if quick else 5e-3
    t_end = 10.0 if quick else 20.0
    wn = float(np.linalg.norm(TF_W0))
    # generalized-alpha (rho_inf = 1) on the Lie group conserves neither |H| nor T exactly;
    # their errors are bounded and O((|w| h)^2) (second order, no secular drift), so
    # (|w| h)^2 (1.1e-4 quick, 2.8e-5 full) is the scale of the method's own error.
    tol_inv = (wn * h) ** 2
    # the phase error of the motion grows linearly in time: (|w| h)^2 |w| t_end
    tol_w = (wn * h) ** 2 * wn * t_end
    out: list[CaseResult] = []
    figs: list[str] = []
    for pinned in (False, True):
        label = "pinned at the centre of mass, gravity" if pinned else "free body"
        src = "exact invariants of the torque-free motion"
        model = torque_free_model(pinned)
        res = dd.simulate(model, t_end, step=dd.FixedStep(h),
                          integrator=dd.GeneralizedAlpha(rho_inf=1.0), output_dt=10 * h)
        q_h = f"max |H - H0| / |H0|, {label}"
        q_t = f"max |T - T0| / T0, {label}"
        q_w = f"max |Omega - Omega_exact| / |Omega0|, {label}"
        src_w = "Euler-Poinsot solution with Jacobi elliptic functions (Landau-Lifshitz 37)"
        if not res.success:
            out += [_failed(case, q, "1", tol, s, res)
                    for q, tol, s in ((q_h, tol_inv, src), (q_t, tol_inv, src),
                                      (q_w, tol_w, src_w))]
            continue
        t = res.time
        H = res["body.angular_momentum"].values
        H0 = TF_J * TF_W0
        dH = float(np.max(np.linalg.norm(H - H0, axis=1)) / np.linalg.norm(H0))
        T = res["energy.kinetic"].values
        T0 = 0.5 * float(np.sum(TF_J * TF_W0 ** 2))
        dT = float(np.max(np.abs(T - T0)) / T0)
        R = res["body.rotation"].values
        Om = np.einsum("tji,tj->ti", R, res["body.angular_velocity"].values)
        Om_ex = euler_free_body_exact(TF_J, TF_W0, t)
        dW = float(np.max(np.linalg.norm(Om - Om_ex, axis=1)) / wn)
        out += [compare(case, q_h, 0.0, dH, "1", tol_inv, src),
                compare(case, q_t, 0.0, dT, "1", tol_inv, src),
                compare(case, q_w, 0.0, dW, "1", tol_w, src_w)]
        if pinned:
            def draw(fig, t=t, Om=Om, Om_ex=Om_ex, H=H, H0=H0):
                ax1, ax2 = fig.subplots(2, 1, sharex=True)
                for i, c in enumerate("xyz"):
                    ax1.plot(t, Om[:, i], label=f"Omega_{c} simulated")
                    ax1.plot(t, Om_ex[:, i], "k--", lw=0.8)
                ax1.set_ylabel("body angular velocity [rad/s]")
                ax1.legend(fontsize=7, title="dashed: exact", title_fontsize=7)
                ax2.plot(t, np.linalg.norm(H - H0, axis=1) / np.linalg.norm(H0))
                ax2.set_ylabel("|H - H0| / |H0|")
                ax2.set_xlabel("time [s]")
                fig.suptitle("torque-free body (pinned at its centre of mass)")
            figs += _figure(figure_dir, "torque_free_body", draw)
    return _finish(out, t0, figs)


@register_case("heavy_top")
def heavy_top(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Heavy symmetric top on a spherical joint: (a) steady precession, (b) nutation from
    rest in precession (Goldstein's cusp motion)."""
    t0 = time.perf_counter()
    case = "heavy_top"
    rho = 0.9  # see the module docstring (rho_inf = 1 is unstable for this constrained top)
    h = 1e-3 if quick else 5e-4
    theta0 = np.radians(30.0)
    w3 = 40.0  # spin [rad/s]
    out: list[CaseResult] = []
    figs: list[str] = []

    # (a) steady precession
    Om = top_steady_precession_rate(TOP_I1, TOP_I3, TOP_M, G, TOP_L, theta0, w3)
    t_end = 1.0 if quick else 2.0  # about one / two precession periods (2 pi / 6.26 s)
    res = dd.simulate(top_model(theta0, w3, Om), t_end, step=dd.FixedStep(h),
                      integrator=dd.GeneralizedAlpha(rho), output_dt=h)
    src = "steady precession m g l = Omega (I3 w3 - I1 Omega cos theta) (Goldstein 5.7)"
    # The fastest motion is the nutation, frequency a = I3 w3 / I1 = 25 rad/s. For a
    # second-order scheme every error below is C (a h)^2 (relative for rates, periods and
    # angles, in rad for the spurious nutation amplitude): (a h)^2 = 6.3e-4 (quick),
    # 1.6e-4 (full). Halving h divides each error by 4.0 (checked for h = 2, 1, 0.5 and
    # 0.25 ms), with C = 0.1 ... 0.7, so the tolerance is C = 1: (a h)^2.
    a_nut = TOP_I3 * w3 / TOP_I1
    tol_rate = (a_nut * h) ** 2
    # spurious nutation in steady precession, from the start-up of the scheme (O(h^2));
    # a 0.1 % error of the initial precession rate would already give 2 dOmega sin(theta) / a
    # = 2.5e-4 rad, a 1 % error 2.5e-3 rad.
    tol_amp = (a_nut * h) ** 2
    if res.success:
        theta, phi, _ = _top_angles(res)
        t = res.time
        rate = float(np.polyfit(t, phi, 1)[0])
        amp = float(theta.max() - theta.min())
        out += [compare(case, "steady precession: mean precession rate", Om, rate, "rad/s",
                        tol_rate, src),
                compare(case, "steady precession: nutation amplitude max-min theta", 0.0, amp,
                        "rad", tol_amp, src)]

        def draw_a(fig, t=t, theta=theta, phi=phi):
            ax1, ax2 = fig.subplots(2, 1, sharex=True)
            ax1.plot(t, np.degrees(theta - theta0))
            ax1.set_ylabel("theta - theta0 [deg]")
            ax2.plot(t, phi - Om * t)
            ax2.set_ylabel("phi - Omega t [rad]")
            ax2.set_xlabel("time [s]")
            fig.suptitle(f"heavy top, steady precession (Omega = {Om:.5f} rad/s)")
        figs += _figure(figure_dir, "heavy_top_steady", draw_a)
    else:
        out += [_failed(case, "steady precession: mean precession rate", "rad/s", tol_rate,
                        src, res),
                _failed(case, "steady precession: nutation amplitude max-min theta", "rad",
                        tol_amp, src, res)]

    # (b) nutation, released with zero precession rate
    ref = top_nutation_reference(TOP_I1, TOP_I3, TOP_M, G, TOP_L, theta0, w3, 0.0)
    n_per = 4 if quick else 8
    t_end = (n_per + 0.5) * ref["T_nut"]
    res = dd.simulate(top_model(theta0, w3, 0.0), t_end, step=dd.FixedStep(h),
                      integrator=dd.GeneralizedAlpha(rho), output_dt=h)
    src = "quadrature of Goldstein's u = cos(theta) cubic (Goldstein 5.7)"
    tol = (a_nut * h) ** 2  # see above (relative errors)
    names = ("nutation period", "precession angle per nutation period",
             "minimum nutation angle", "maximum nutation angle")
    units = ("s", "rad", "rad", "rad")
    tols = (tol, tol, tol, tol)
    if res.success:
        theta, phi, udot = _top_angles(res)
        t = res.time
        # cusps (u maximum, theta minimum): udot crosses zero downwards
        tc = crossings(t, udot, direction=-1)
        tc = tc[tc > 0.5 * ref["T_nut"]]  # skip the release instant
        T_sim = float((tc[-1] - tc[0]) / (len(tc) - 1))
        phic = np.interp(tc, t, phi)
        dphi_sim = float((phic[-1] - phic[0]) / (len(tc) - 1))
        th_min = float(-_peak(t, -theta))
        th_max = float(_peak(t, theta))
        sims = (T_sim, dphi_sim, th_min, th_max)
        refs = (ref["T_nut"], ref["dphi"], ref["theta_min"], ref["theta_max"])
        out += [compare(case, f"nutation: {q}", rv, sv, u, tol, src)
                for q, u, tol, rv, sv in zip(names, units, tols, refs, sims, strict=True)]

        def draw_b(fig, t=t, theta=theta, phi=phi):
            ax1, ax2 = fig.subplots(2, 1, sharex=True)
            ax1.plot(t, np.degrees(theta), label="simulated")
            for v in (ref["theta_min"], ref["theta_max"]):
                ax1.axhline(np.degrees(v), color="k", ls="--", lw=0.8)
            ax1.set_ylabel("nutation theta [deg]")
            ax1.legend(fontsize=8, title="dashed: exact turning angles", title_fontsize=8)
            ax2.plot(t, phi)
            ax2.set_ylabel("precession phi [rad]")
            ax2.set_xlabel("time [s]")
            fig.suptitle("heavy top released with zero precession rate")
        figs += _figure(figure_dir, "heavy_top_nutation", draw_b)
    else:
        out += [_failed(case, f"nutation: {q}", u, tol, src, res)
                for q, u, tol in zip(names, units, tols, strict=True)]
    return _finish(out, t0, figs)


@register_case("pendulum")
def pendulum(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Physical pendulum on a hinge: small- and large-amplitude periods."""
    t0 = time.perf_counter()
    case = "pendulum"
    h = 2e-3 if quick else 1e-3
    rho = 0.9
    w0 = np.sqrt(PEND_M * G * PEND_D / PEND_IO)
    T_lin = 2.0 * np.pi / w0
    # relative period error of generalized alpha: O((w0 h)^2); (w0 h)^2 = 3.9e-5 (quick),
    # 9.7e-6 (full); measured: 0.1 (2 deg) and 0.35 (120 deg) of it. For 120 deg the motion
    # is slower near the turning points but its highest frequency content is still ~w0.
    tol_num = (w0 * h) ** 2
    out: list[CaseResult] = []
    histories = []
    for deg in (2.0, 120.0):
        th0 = np.radians(deg)
        T_ex = pendulum_period_exact(PEND_IO, PEND_M, G, PEND_D, th0)
        n_half = 4 if quick else 6  # half periods measured
        t_end = (0.5 * n_half + 0.5) * T_ex
        res = dd.simulate(pendulum_model(th0), t_end, step=dd.FixedStep(h),
                          integrator=dd.GeneralizedAlpha(rho), output_dt=h)
        checks = []
        if deg < 10.0:
            # linear theory: the exact period exceeds 2 pi sqrt(I/mgd) by theta0^2 / 16
            # (7.6e-5 at 2 deg) -- the tolerance is that bound plus the numerical error.
            checks.append((f"period, {deg:g} deg vs linear theory 2 pi sqrt(I_o/(m g d))",
                           T_lin, th0 ** 2 / 16 * 1.01 + tol_num,
                           "small-amplitude pendulum 2 pi sqrt(I_o/(m g d))"))
        checks.append((f"period, {deg:g} deg vs exact 4 sqrt(I_o/(m g d)) K(k^2)", T_ex,
                       tol_num, "complete elliptic integral, k = sin(theta0/2)"))
        if not res.success:
            out += [_failed(case, q, "s", tol, s, res) for q, _, tol, s in checks]
            continue
        th = _pendulum_angle(res)
        tc = crossings(res.time, th)
        T_sim = float(2.0 * (tc[-1] - tc[0]) / (len(tc) - 1))
        out += [compare(case, q, ref, T_sim, "s", tol, s) for q, ref, tol, s in checks]
        histories.append((deg, res.time, th))

    def draw(fig):
        axs = fig.subplots(len(histories), 1, squeeze=False)[:, 0]
        for ax, (deg, t, th) in zip(axs, histories, strict=True):
            ax.plot(t, np.degrees(th), label="simulated")
            ax.plot(t, np.degrees(pendulum_angle_exact(PEND_IO, PEND_M, G, PEND_D,
                                                       np.radians(deg), t)),
                    "k--", lw=0.8, label="exact")
            ax.set_ylabel(f"theta [deg] ({deg:g} deg)")
            ax.legend(fontsize=8)
        axs[-1].set_xlabel("time [s]")
        fig.suptitle("physical pendulum")
    figs = _figure(figure_dir, "pendulum", draw) if histories else []
    return _finish(out, t0, figs)


@register_case("slider_crank")
def slider_crank(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Slider-crank: kinematics at constant crank speed and static reactions."""
    t0 = time.perf_counter()
    case = "slider_crank"
    out: list[CaseResult] = []
    figs: list[str] = []
    # (a) kinematics over one revolution at 1 rev/s
    h = 2e-3 if quick else 5e-4
    w = 2.0 * np.pi
    res = dd.simulate(slider_crank_model(0.0, ("speed", w)), 1.0, step=dd.FixedStep(h),
                      integrator=dd.GeneralizedAlpha(0.9), output_dt=h)
    q = "piston position over a revolution: max |x - x(theta)|"
    src = "x = r cos(theta) + sqrt(l^2 - r^2 sin^2 theta)"
    # the position is fixed by the constraints alone (crank angle prescribed); Newton stops
    # at constraint violations below phi_tol = 1e-10 [m or rad] per row, so a few 1e-10 m
    # of position error are allowed: 1e-9 m (1e-8 of the crank radius).
    tol = 1e-9
    if res.success:
        t = res.time
        x = res["slider.position"].values[:, 0]
        th = res["crank_drive.angle"].values
        err_x = float(np.max(np.abs(x - slider_crank_position(SC_R, SC_L, w * t))))
        err_th = float(np.max(np.abs(th - w * t)))
        out += [compare(case, q, 0.0, err_x, "m", tol, src),
                compare(case, "crank angle vs prescribed w t: max error", 0.0, err_th, "rad",
                        1e-9, "speed driver, theta = w t")]

        def draw(fig, t=t, x=x):
            ax1, ax2 = fig.subplots(2, 1, sharex=True)
            ax1.plot(np.degrees(w * t), x, label="simulated")
            ax1.plot(np.degrees(w * t), slider_crank_position(SC_R, SC_L, w * t), "k--",
                     lw=0.8, label="exact")
            ax1.set_ylabel("piston x [m]")
            ax1.legend(fontsize=8)
            ax2.plot(np.degrees(w * t), x - slider_crank_position(SC_R, SC_L, w * t))
            ax2.set_ylabel("error [m]")
            ax2.set_xlabel("crank angle [deg]")
            fig.suptitle("slider-crank kinematics, r = 0.1 m, l = 0.3 m")
        figs += _figure(figure_dir, "slider_crank", draw)
    else:
        out += [_failed(case, q, "m", tol, src, res)]

    # (b) statics: the crank held at several angles by an angle driver, piston force P
    P = 100.0
    angles = (30.0, 120.0, 250.0) if quick else (20.0, 60.0, 100.0, 150.0, 200.0, 250.0,
                                                  300.0, 340.0)
    src = "virtual work: T = P r sin(theta + phi) / cos(phi), N = P tan(phi)"
    # statics is exact up to the Newton tolerances (residual 1e-8 relative, constraints
    # 1e-10): 1e-7 relative on the torque (and absolute 1e-7 N on the normal force, which
    # vanishes at dead centres).
    for deg in angles:
        thr = np.radians(deg)
        T_ref, N_ref = slider_crank_statics(SC_R, SC_L, P, thr)
        model = slider_crank_model(thr, ("angle", 0.0), piston_force=P)
        outputs = dd.element_outputs(model, dd.solve_static(model))
        T_drv = outputs["crank_drive"]["torque"]
        N_sim = outputs["guide_joint"]["force_y"]
        # the driver holds the crank: its torque on the crank balances the gas torque
        out.append(compare(case, f"statics {deg:g} deg: driver torque (= -T)", -T_ref, T_drv,
                           "N m", 1e-7, src))
        out.append(compare(case, f"statics {deg:g} deg: guide normal force on the slider (y)",
                           N_ref, N_sim, "N", 1e-7, src))
    return _finish(out, t0, figs)


@register_case("screw")
def screw(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Nut on a screw joint turned by a speed driver through several revolutions."""
    t0 = time.perf_counter()
    case = "screw"
    h = 2e-3 if quick else 5e-4
    revs = 3 if quick else 10
    speed = 2.0 * np.pi * 2.0  # 2 rev/s
    t_end = revs / 2.0
    res = dd.simulate(screw_model(speed), t_end, step=dd.FixedStep(h),
                      integrator=dd.GeneralizedAlpha(0.9), output_dt=5 * h)
    src = "screw kinematics z = pitch theta / (2 pi)"
    q1 = f"axial travel vs pitch x angle / 2 pi over {revs} revolutions: max error"
    q2 = f"axial travel after {revs} revolutions"
    q3 = "driver torque lifting the nut: m g pitch / (2 pi)"
    # position fixed by the constraints only: constraint tolerance 1e-10 m, allow 1e-9 m
    tol = 1e-9
    if not res.success:
        return _finish([_failed(case, q1, "m", tol, src, res)], t0, [])
    t = res.time
    z = res["nut.position"].values[:, 2]
    ang = res["turn.angle"].values
    jang = res["screw.angle"].values
    err = float(np.max(np.abs(z - SCREW_PITCH * ang / (2.0 * np.pi))))
    out = [compare(case, q1, 0.0, err, "m", tol, src),
           compare(case, q2, revs * SCREW_PITCH, z[-1], "m", 1e-8, src + ", angle = w t"),
           compare(case, "accumulated joint angle after the run", speed * t_end,
                   float(jang[-1]), "rad", 1e-9, "speed driver, theta = w t")]
    # At constant speed the only load is the weight: power balance T w = m g v. The torque
    # is a multiplier: its mean over the run is exact up to the Newton tolerance (1e-8
    # relative), tolerance 1e-6. Step to step it carries the (-1)^n oscillation of index-3
    # multipliers, excited by the round-off of the accumulated angle (eps |theta| ~ 1e-14
    # rad after 10 revolutions) amplified by J / (beta h^2): ~5e-7 N m = 2e-5 relative at
    # h = 0.5 ms; tolerance on the largest deviation 1e-4.
    torque = res["turn.torque"].values[1:]
    T_ref = SCREW_M * G * SCREW_PITCH / (2.0 * np.pi)
    out.append(compare(case, q3 + ", mean over the run", T_ref, float(np.mean(torque)),
                       "N m", 1e-6, "power balance of a frictionless screw"))
    out.append(compare(case, q3 + ", largest deviation", T_ref,
                       float(torque[np.argmax(np.abs(torque - T_ref))]), "N m", 1e-4,
                       "power balance of a frictionless screw"))

    def draw(fig):
        ax1, ax2 = fig.subplots(2, 1, sharex=True)
        ax1.plot(t, z, label="simulated")
        ax1.plot(t, SCREW_PITCH * speed * t / (2 * np.pi), "k--", lw=0.8, label="exact")
        ax1.set_ylabel("axial travel [m]")
        ax1.legend(fontsize=8)
        ax2.plot(t, z - SCREW_PITCH * ang / (2 * np.pi))
        ax2.set_ylabel("error [m]")
        ax2.set_xlabel("time [s]")
        fig.suptitle(f"screw joint, pitch {SCREW_PITCH * 1e3:g} mm")
    return _finish(out, t0, _figure(figure_dir, "screw", draw))


def convergence_errors(hs: Sequence[float], t_final: float, theta0: float = np.radians(120.0),
                       rho_inf: float = 0.9) -> tuple[np.ndarray, list[Any]]:
    """Global position error [m] of the pendulum's centre of mass at ``t_final`` for each
    step size (exact solution from Jacobi elliptic functions)."""
    model = pendulum_model(theta0)
    th = float(pendulum_angle_exact(PEND_IO, PEND_M, G, PEND_D, theta0, t_final))
    x_ex = PEND_D * np.array([np.sin(th), 0.0, -np.cos(th)])
    errs, runs = [], []
    for h in hs:
        # Newton: the default residual test (1e-8 relative) changes the positions by about
        # tol * |r| * beta h^2 / m < 1e-15 m per step, far below the smallest error measured
        # (~1e-7 m); constraints to 1e-12. (tol = 1e-12 is below the round-off of the
        # penalty terms and cannot be met.)
        res = dd.simulate(model, t_final, step=dd.FixedStep(h),
                          integrator=dd.GeneralizedAlpha(rho_inf),
                          newton=dd.Newton(tol=1e-8, phi_tol=1e-12),
                          output_times=[0.0, t_final])
        runs.append(res)
        if not res.success:
            errs.append(np.nan)
            continue
        errs.append(float(np.linalg.norm(res["rod.position"].values[-1] - x_ex)))
    return np.asarray(errs), runs


@register_case("convergence")
def convergence(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Order of the global error on the 120 deg pendulum (exact elliptic-function solution)."""
    t0 = time.perf_counter()
    case = "convergence"
    h0 = 4e-3
    n = 4 if quick else 5
    hs = h0 / 2.0 ** np.arange(n)
    t_final = 0.5 if quick else 1.0
    rho = 0.9
    errs, runs = convergence_errors(hs, t_final, rho_inf=rho)
    src = "generalized alpha is second order (Chung & Hulbert 1993; Bruls et al. 2012)"
    q = (f"slope of log(error) vs log(h), pendulum 120 deg, rho_inf = {rho}, "
         f"h = {hs[0]:g}..{hs[-1]:g} s")
    # slope in [1.8, 2.2]
    if not np.all(np.isfinite(errs)):
        bad = next(r for r in runs if not r.success)
        return _finish([_failed(case, q, "1", 0.1, src, bad)], t0, [])
    slope = float(np.polyfit(np.log(hs), np.log(errs), 1)[0])
    r = compare(case, q, 2.0, slope, "1", 0.1, src)  # relative 0.1 <=> slope in [1.8, 2.2]
    out = [r]
    # the finest error must stay well above round-off / Newton noise (asymptotic range)
    out.append(compare(case, f"position error at t = {t_final:g} s, h = {hs[-1]:g} s",
                       0.0, float(errs[-1]), "m", 1e-4,
                       "exact: sin(theta/2) = k sn(K - w0 t, k)"))

    def draw(fig):
        ax = fig.subplots()
        ax.loglog(hs, errs, "o-", label=f"simulated (slope {slope:.3f})")
        ax.loglog(hs, errs[0] * (hs / hs[0]) ** 2, "k--", lw=0.8, label="slope 2")
        ax.set_xlabel("step size h [s]")
        ax.set_ylabel(f"position error at t = {t_final:g} s [m]")
        ax.legend()
        fig.suptitle("global error of the pendulum (120 deg)")
    return _finish(out, t0, _figure(figure_dir, "convergence", draw))


def energy_scale(res: Any) -> float:
    """Energy exchanged in a run [J]: ``max|T - T0| + max|V - V0| + max|W_in| + D(t_end)``
    (kinetic, potential, supplied work, dissipated energy)."""
    T = res["energy.kinetic"].values
    V = res["energy.potential"].values
    W = res["energy.work_in"].values
    D = res["energy.dissipated"].values
    return float(np.max(np.abs(T - T[0])) + np.max(np.abs(V - V[0])) + np.max(np.abs(W))
                 + abs(D[-1]))


def flywheel_model(torque: Any) -> dd.Model:
    """A flywheel (J = 0.05 kg m^2 about z) on a hinge, driven by a torque time function."""
    spec = dd.Spec()
    spec.add_rigid_body("wheel", 5.0, [0.03, 0.03, 0.05])
    spec.add_marker("bearing", "ground", axis=(0.0, 0.0, 1.0))
    spec.add_marker("wheel_axis", "wheel", axis=(0.0, 0.0, 1.0))
    spec.add(dd.Hinge("wheel_bearing", "bearing", "wheel_axis"))
    spec.add(dd.Torque("motor", "wheel_axis", vector=(0.0, 0.0, 1.0), function=torque))
    return dd.compile_model(spec)


@register_case("energy_balance")
def energy_balance(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Energy account ``(T + V) - (T0 + V0) - W_in + D = 0`` with dissipation, work of a
    torque and work of a driver; rho_inf = 1 (and 0.9, the setting of the constrained
    cases above)."""
    t0 = time.perf_counter()
    case = "energy_balance"
    h = 2e-3 if quick else 1e-3
    t_end = 2.0
    th_top = np.radians(30.0)
    runs = [
        ("pendulum 120 deg with torsional spring-damper (dissipation)",
         lambda: pendulum_model(np.radians(120.0), damper=(2.0, 0.05)), (1.0, 0.9)),
        ("flywheel driven by a torque Ramp + SmoothStep (work in)",
         lambda: flywheel_model(dd.Ramp(0.0, 0.5, 0.0, 2.0)
                                + dd.SmoothStep(1.0, 1.5, 0.0, -3.0)), (1.0, 0.9)),
        ("slider-crank from rest at a dead centre up to 2 rev/s against a guide "
         "spring-damper (driver work)",
         lambda: slider_crank_model(0.0, ("speed", dd.SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)),
                                    guide_spring=(2000.0, 5.0)), (1.0, 0.9)),
        # rho_inf = 1 is unstable for the top (growing (-1)^n multiplier oscillation)
        ("heavy top nutating (3D, spherical joint)",
         lambda: top_model(th_top, 40.0, 0.0), (0.9,)),
    ]
    # The balance error of a second-order scheme is O(h^2) relative to the energy exchanged
    # (powers integrated by the trapezoidal rule over each step); 1e-3 is the required
    # accuracy of the energy account; what is measured is 1e-7 ... 2e-5.
    tol = 1e-3
    out: list[CaseResult] = []
    hist = []
    for label, build, rhos in runs:
        model = build()
        for rho in rhos:
            res = dd.simulate(model, t_end, step=dd.FixedStep(h),
                              integrator=dd.GeneralizedAlpha(rho_inf=rho), output_dt=5 * h)
            q = f"max |balance error| / energy exchanged, rho_inf = {rho:g}: {label}"
            src = "energy conservation: (T + V) - (T0 + V0) = W_in - D"
            if not res.success:
                out.append(_failed(case, q, "1", tol, src, res))
                continue
            scale = energy_scale(res)
            err = float(np.max(np.abs(res["energy.balance_error"].values)) / scale)
            out.append(compare(case, q, 0.0, err, "1", tol,
                               src + f"; energy exchanged {scale:.4g} J"))
            if rho == rhos[0]:
                hist.append((f"{label}, rho_inf = {rho:g}", res))

    def draw(fig):
        axs = fig.subplots(len(hist), 1, squeeze=False)[:, 0]
        for ax, (label, res) in zip(axs, hist, strict=True):
            t = res.time
            for name in ("kinetic", "potential", "work_in", "dissipated", "balance_error"):
                ax.plot(t, res[f"energy.{name}"].values, label=name)
            ax.set_title(label, fontsize=8)
            ax.set_ylabel("[J]")
        axs[0].legend(fontsize=7)
        axs[-1].set_xlabel("time [s]")
    figs = _figure(figure_dir, "energy_balance", draw) if hist else []
    return _finish(out, t0, figs)


# ---------------------------------------------------------------------------------------------
# contact, friction, impact and lubrication (drivedyn.elements.contact and friends)
# ---------------------------------------------------------------------------------------------


def impact_restitution_ode(chi: float, n: float, K: float, m: float, v0: float,
                           g: float = 0.0) -> float:
    """Restitution (rebound over approach speed at delta = 0) of a mass ``m`` hitting a rigid
    wall at ``v0`` [m/s] with the force ``K delta^n (1 + chi deltadot / v0)`` (never pulling)
    and a constant acceleration ``g`` towards the wall during the contact: scipy DOP853 with
    tolerances 1e-12. With ``g = 0`` it equals the exact relation ``phi(chi) = phi(-e chi)``."""
    from scipy.integrate import solve_ivp

    def f(t, y):
        d, v = y
        F = K * d**n * (1.0 + chi * v / v0) if d > 0.0 else 0.0
        return [v, g - max(F, 0.0) / m]

    def out(t, y):
        return y[0]

    out.terminal = True
    out.direction = -1
    tc = 10.0 * (m * v0**2 / K) ** (1.0 / (n + 1.0)) / v0
    sol = solve_ivp(f, [0.0, 50.0 * tc], [1e-300, v0], events=out, rtol=1e-12, atol=1e-30,
                    method="DOP853", first_step=tc * 1e-6)
    return -float(sol.y_events[0][0][1]) / v0


@register_case("bouncing_ball")
def bouncing_ball(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """The seeds' bouncing ball (seed 000: Lankarani-Nikravesh law, e = 0.8, n = 1.5,
    K = 1e10 N/m^1.5, h0 = 1 m, m = 0.85 kg, g = 10 m/s^2): every bounce against an ODE
    reference that includes gravity during the contact, apexes, energy balance."""
    from drivedyn.library.bouncing_ball import plot_height, run_bounce

    t0 = time.perf_counter()
    case = "bouncing_ball"
    run = run_bounce(t_end=1.5 if quick else 3.0)
    src_ode = ("impact ODE m deltaddot = m g - K delta^n (1 + chi deltadot/v_s), scipy "
               "DOP853 1e-12")
    if not run.success or not run.restitution:
        return _finish([_failed(case, "bounces", "1", 1e-5, src_ode, run)], t0, [])
    K, n, m, g = 1e10, 1.5, 0.85, 10.0
    out = [compare(case, "approach speed of the first impact", np.sqrt(2 * g * 1.0),
                   run.impact_speeds[0], "m/s", 1e-10, "free fall from h0: sqrt(2 g h0)")]
    # tolerance: the time integration at contact onset and separation (force kinks) is
    # measured at ~1e-6 with the benchmark's step control (rtol 1e-6, atol 1e-12)
    for i, (v, e) in enumerate(zip(run.impact_speeds, run.restitution, strict=True)):
        out.append(compare(case, f"restitution of bounce {i + 1} (approach {v:.4f} m/s)",
                           impact_restitution_ode(run.chi, n, K, m, v, g), e, "1", 1e-5,
                           src_ode))
    out.append(compare(case, "restitution predicted by the exact relation (no gravity)",
                       run.e_predicted, run.restitution[0], "1", 3e-4,
                       "chi - ln(1 + chi) = -e chi - ln(1 - e chi); gravity during the "
                       "contact lowers e by ~1e-4"))
    for i, h in enumerate(run.apex_heights):
        out.append(compare(case, f"apex height after bounce {i + 1}",
                           run.rebound_speeds[i] ** 2 / (2 * g), h, "m", 1e-5,
                           "free flight: v_rebound^2 / (2 g)"))
    res = run.results
    lost = (res["energy.kinetic"].values[0] + res["energy.potential"].values[0]
            - res["energy.kinetic"].values[-1] - res["energy.potential"].values[-1])
    out.append(compare(case, "energy lost (kinetic + potential) vs dissipated by the contact",
                       run.dissipated, lost, "J", 1e-3, "energy balance"))

    def draw(fig):
        plot_height(run, fig)

    out[0].source += f"; {run.steps} steps, {run.wall_s:.2f} s"
    return _finish(out, t0, _figure(figure_dir, "bouncing_ball", draw))


@register_case("restitution_laws")
def restitution_laws(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Achieved restitution of every continuous-impact law for e = 0.2, 0.5, 0.8, 0.95:
    simulated collision without gravity vs the exact relation at the law's chi."""
    from drivedyn.elements.impact_laws import IMPACT_LAWS, restitution_from_chi
    from drivedyn.library.bouncing_ball import restitution_table

    t0 = time.perf_counter()
    case = "restitution_laws"
    targets = (0.5, 0.8) if quick else (0.2, 0.5, 0.8, 0.95)
    rows = restitution_table(targets=targets)
    src = "exact relation chi - ln(1 + chi) = -e chi - ln(1 - e chi) at the law's chi"
    # the collision runs resolve each impact with ~250 steps: 2e-6 measured, tolerance 2e-5
    out = [compare(case, f"{r['law']}, e = {r['e_target']:g} (chi = {r['chi']:.4g})",
                   r["e_predicted"], r["e_simulated"], "1", 2e-5, src) for r in rows]

    def draw(fig):
        ax = fig.subplots()
        es = np.linspace(0.05, 0.99, 200)
        from drivedyn.elements.impact_laws import damping_factor

        for law in IMPACT_LAWS:
            ax.plot(es, [restitution_from_chi(damping_factor(law, e)) for e in es], lw=1,
                    label=f"{law} (exact relation)")
            pts = [(r["e_target"], r["e_simulated"]) for r in rows if r["law"] == law]
            ax.plot(*zip(*pts, strict=True), "ko", ms=3)
        ax.plot([0, 1], [0, 1], "k:", lw=0.8)
        ax.set_xlabel("restitution given to the law")
        ax.set_ylabel("restitution achieved")
        ax.legend(fontsize=7)
        fig.suptitle("continuous-impact laws: achieved restitution (dots: simulated)")
    return _finish(out, t0, _figure(figure_dir, "restitution_laws", draw))


@register_case("contact_friction")
def contact_friction(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """A block on an incline (contact point at the centre of mass): regularised Coulomb
    friction (creep speed below tan(theta) = mu, Coulomb acceleration above) and the
    augmented-Lagrangian stick/slip contact (true sticking, Coulomb acceleration)."""
    t0 = time.perf_counter()
    case = "contact_friction"
    m, mu, K = 2.0, 0.5, 1e6
    src_a = "sliding block: a = g (sin(theta) - mu cos(theta))"

    def block(theta, friction=None, mu_al=None):
        R = _ry(theta)
        spec = dd.Spec(gravity=(0.0, 0.0, -G))
        spec.add_marker("slope", dd.GROUND, rotation=R)
        pen = 0.0 if mu_al is not None else m * G * np.cos(theta) / K
        spec.add_rigid_body("block", m, (0.01, 0.01, 0.01), position=-pen * R[:, 2])
        spec.add_marker("foot", "block")
        if mu_al is not None:
            spec.add(dd.UnilateralContact("contact", "slope", "foot", mu=mu_al))
        else:
            law = dd.NormalLaw(K, 1.0, law="penalty", damping=2.0 * np.sqrt(K * m))
            spec.add(dd.PlaneContact("contact", "slope", "foot", law=law, friction=friction))
        res = dd.simulate(dd.compile_model(spec), 0.6, integrator=dd.GeneralizedAlpha(0.9),
                          step=dd.FixedStep(1e-3), output_dt=1e-3)
        t_axis = R[:, 0]
        return res, res["block.position"].values @ t_axis, res["block.velocity"].values @ t_axis

    out: list[CaseResult] = []
    hist = []
    eps = 1e-3
    for label, kw in (("regularised Coulomb", {"friction": dd.FrictionLaw(mu, eps_v=eps)}),
                      ("augmented Lagrangian", {"mu_al": mu})):
        th_slide = np.arctan(0.7)
        res, s, v = block(th_slide, **kw)
        q = f"{label}: acceleration on a slope tan(theta) = 0.7 > mu = {mu}"
        if not res.success:
            out.append(_failed(case, q, "m/s^2", 1e-6, src_a, res))
            continue
        sel = res.time > 0.1
        a = float(np.polyfit(res.time[sel], v[sel], 1)[0])
        out.append(compare(case, q, G * (np.sin(th_slide) - mu * np.cos(th_slide)), a,
                           "m/s^2", 1e-6, src_a))
        th_stick = np.arctan(0.3)
        res, s, v = block(th_stick, **kw)
        late = res.time > 0.3
        if label == "augmented Lagrangian":
            out.append(compare(case, f"{label}: largest displacement on tan(theta) = 0.3 < mu",
                               0.0, float(np.max(np.abs(s - s[0]))), "m", 1e-9,
                               "sticking: no motion (Newton tolerance)"))
        else:
            v_c = eps * (1 - np.sqrt(1 - 0.3 / mu))
            out.append(compare(case, f"{label}: creep speed on tan(theta) = 0.3 < mu",
                               v_c, float(np.mean(v[late])), "m/s", 1e-5,
                               "mu_R(v_c) = tan(theta): v_c = eps_v (1 - sqrt(1 - tan/mu))"))
        hist.append((label, res.time, s - s[0]))

    def draw(fig):
        ax = fig.subplots()
        for label, t, s in hist:
            ax.semilogy(t[1:], np.abs(s[1:]) + 1e-12, label=f"{label}, tan(theta) = 0.3")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("|displacement along the slope| + 1e-12 [m]")
        ax.legend(fontsize=8)
        fig.suptitle("block held by friction: regularised creep vs augmented-Lagrangian stick")
    return _finish(out, t0, _figure(figure_dir, "contact_friction", draw) if hist else [])


@register_case("thrust_washer")
def thrust_washer(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """A gear driven at constant speed and pressed on a thrust washer: driver torque vs the
    friction torque of the seeds M = 2 pi mu_R (F/S)(r_ext^3 - r_int^3)/3."""
    t0 = time.perf_counter()
    case = "thrust_washer"
    ri, re, K, mg = 0.02, 0.04, 1e9, 0.5
    out: list[CaseResult] = []
    src = "M = 2 pi mu_R (F/S) (r_ext^3 - r_int^3) / 3 (seeds), mu_R at v = r_m omega"
    for F, omega, mu, eps in ((200.0, 10.0, 0.12, 1e-3), (100.0, 0.5, 0.1, 0.05)):
        spec = dd.Spec()
        spec.add_marker("axis", dd.GROUND)
        spec.add_marker("washer", dd.GROUND)
        spec.add_rigid_body("gear", mg, (2e-4, 2e-4, 4e-4), position=(0, 0, -F / K),
                            angular_velocity=(0, 0, omega))
        spec.add_marker("face", "gear")
        spec.add(dd.Cylindrical("guide", "axis", "face"))
        spec.add(dd.JointDriver("motor", "guide", omega, quantity="speed"))
        spec.add(dd.Force("thrust", "face", vector=(0, 0, -F)))
        law = dd.NormalLaw(K, 1.0, law="penalty", damping=2.0 * np.sqrt(K * mg))
        friction = dd.FrictionLaw(mu, eps_v=eps)
        spec.add(dd.ThrustWasherContact("contact", "washer", "face", law=law, r_int=ri,
                                        r_ext=re, friction=friction))
        res = dd.simulate(dd.compile_model(spec), 0.2, integrator=dd.GeneralizedAlpha(0.8),
                          step=dd.FixedStep(1e-4), output_dt=1e-3)
        q = f"driver torque, F = {F:g} N, omega = {omega:g} rad/s, mu = {mu:g}"
        if not res.success:
            out.append(_failed(case, q, "N m", 1e-6, src, res))
            continue
        rm = 2 * (re**3 - ri**3) / (3 * (re**2 - ri**2))
        mu_r = float(friction.coefficient(rm * omega))
        M = 2 * np.pi * mu_r * (F / (np.pi * (re**2 - ri**2))) * (re**3 - ri**3) / 3
        out.append(compare(case, q + f" (mu_R = {mu_r:.4g})", M,
                           float(np.mean(res["motor.torque"].values[res.time > 0.1])),
                           "N m", 1e-6, src))
    return _finish(out, t0, [])


@register_case("squeeze_film")
def squeeze_film(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Two annular faces squeezing the oil film under a constant load: film thickness vs the
    closed form 1/h^2 = 1/h0^2 + 4 F t / (3 pi mu C)."""
    from drivedyn.elements.squeeze_film import annulus_factor

    t0 = time.perf_counter()
    case = "squeeze_film"
    F, h0, mu, ri, ro = 100.0, 20e-6, 0.01, 0.015, 0.03
    C = annulus_factor(ri, ro)
    spec = dd.Spec()
    spec.add_marker("housing_face", dd.GROUND)
    spec.add_rigid_body("plate", 0.01, (1e-6, 1e-6, 2e-6), position=(0, 0, h0),
                        velocity=(0, 0, -F * h0**3 / (1.5 * np.pi * mu * C)))
    spec.add_marker("plate_face", "plate")
    spec.add(dd.SqueezeFilm("film", "housing_face", "plate_face", viscosity=mu, r_int=ri,
                            r_ext=ro, roughness=1e-7))
    spec.add(dd.Force("load", "plate_face", vector=(0, 0, -F)))
    t_end = 0.25 if quick else 0.5
    res = dd.simulate(dd.compile_model(spec), t_end, integrator=dd.GeneralizedAlpha(0.8),
                      step=dd.FixedStep(1e-3), output_dt=1e-2)
    src = "Reynolds squeeze film of an annulus: 1/h^2 = 1/h0^2 + 4 F t / (3 pi mu C)"
    q = f"film thickness at t = {t_end:g} s"
    if not res.success:
        return _finish([_failed(case, q, "m", 2e-5, src, res)], t0, [])
    t = res.time
    h = res["film.film_thickness"].values
    h_ref = 1.0 / np.sqrt(1 / h0**2 + 4 * F * t / (3 * np.pi * mu * C))
    # second-order integration of a smooth motion with h = 1 ms: ~1e-6 relative measured
    out = [compare(case, q, h_ref[-1], h[-1], "m", 2e-5, src),
           compare(case, "largest relative error of h(t) over the run", 0.0,
                   float(np.max(np.abs(h / h_ref - 1))), "1", 2e-5, src),
           compare(case, "work of the load vs energy dissipated by the film",
                   float(res["energy.work_in"].values[-1]),
                   float(res["film.dissipated_energy"].values[-1]), "J", 1e-4,
                   "energy balance")]

    def draw(fig):
        ax = fig.subplots()
        ax.plot(t, h * 1e6, label="drivedyn")
        ax.plot(t, h_ref * 1e6, "k--", lw=0.8, label="closed form")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("film thickness [um]")
        ax.legend()
        fig.suptitle(f"squeeze film, annulus {ri * 1e3:g}-{ro * 1e3:g} mm, F = {F:g} N")
    return _finish(out, t0, _figure(figure_dir, "squeeze_film", draw))


# ---------------------------------------------------------------------------------------------
# gear pairs (element drivedyn.elements.gears.GearPair)
# ---------------------------------------------------------------------------------------------

GEAR_Z = (0.0, 0.0, 1.0)


def gear_pair_model(za: int = 20, zb: int = 40, mn: float = 3e-3, beta: float = 0.0,
                    internal: str | None = None, inertia: tuple[float, float] = (2e-3, 8e-3),
                    **kw: Any) -> tuple[dd.Spec, Any]:
    """Wheel A at the origin, wheel B at the working centre distance along x, both on hinges
    to the ground about global z; ``kw`` goes to :class:`~drivedyn.GearPair`. Returns the
    spec (to be completed) and the :class:`CylindricalPair` geometry."""
    from drivedyn.elements.gear_geometry import CylindricalPair

    geo = CylindricalPair.build(za, -zb if internal == "b" else zb, mn, np.radians(20.0), beta)
    a = geo.centre_distance
    spec = dd.Spec()
    spec.add_rigid_body("A", 1.0, (1e-3, 1e-3, inertia[0]))
    spec.add_rigid_body("B", 2.0, (inertia[1],) * 3, position=(a, 0.0, 0.0))
    spec.add_marker("gA", dd.GROUND, axis=GEAR_Z)
    spec.add_marker("mA", "A", axis=GEAR_Z)
    spec.add_marker("gB", dd.GROUND, position=(a, 0.0, 0.0), axis=GEAR_Z)
    spec.add_marker("mB", "B", axis=GEAR_Z)
    spec.add(dd.Hinge("hA", "gA", "mA"))
    spec.add(dd.Hinge("hB", "gB", "mB"))
    spec.add(dd.GearPair("g", "mA", "mB", za, zb, mn, 0.02, helix_angle=beta, internal=internal,
                         **kw))
    return spec, geo


@register_case("gear_pair")
def gear_pair(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Gear pair element: helical force components and deflection (statics), ISO 6336-1
    method B worked example, mesh natural frequency, kinematic ratio over 120 revolutions,
    worm efficiency with tooth friction."""
    from drivedyn.elements.gear_geometry import CylindricalPair, iso6336_mesh_stiffness
    from drivedyn.elements.gears import mesh_info

    t0 = time.perf_counter()
    case = "gear_pair"
    out: list[CaseResult] = []
    an = np.radians(20.0)

    # statics: A held, 100 N m on B; exact to the Newton tolerance (1e-8 relative measured
    # 1e-12), tolerance 1e-9
    beta = np.radians(20.0)
    spec, geo = gear_pair_model(beta=beta, helix_angle_b=-beta, stiffness=3e8)
    spec.add(dd.JointDriver("hold", "hA", 0.0, quantity="angle"))
    spec.add(dd.Torque("T", "mB", vector=(0.0, 0.0, 100.0)))
    m = dd.compile_model(spec)
    o = dd.element_outputs(m, dd.solve_static(m))["g"]
    Ft = o["tangential_force"]
    src = "DIN 3990 / ISO 6336 helical mesh forces, 20/40 teeth, m_n 3 mm, beta 20 deg"
    out += [
        compare(case, "tangential force x r_B / torque", 1.0, Ft * abs(geo.r2) / 100.0, "1",
                1e-9, "moment balance of wheel B"),
        compare(case, "axial force / (F_t tan beta)", 1.0, -o["axial_force"] / (Ft * np.tan(beta)),
                "1", 1e-9, src),
        compare(case, "radial force / (F_t tan alpha_n / cos beta)", 1.0,
                o["radial_force"] / (Ft * np.tan(an) / np.cos(beta)), "1", 1e-9, src),
        compare(case, "normal force / (F_t / (cos alpha_n cos beta))", 1.0,
                o["normal_force"] * np.cos(an) * np.cos(beta) / Ft, "1", 1e-9, src),
        compare(case, "static mesh deflection [F_n / k_m]", o["normal_force"] / 3e8,
                o["deflection"], "m", 1e-9, "spring law along the tooth normal"),
    ]

    # ISO 6336-1 method B, z = 20/40, m_n = 3 mm, alpha_n = 20 deg, beta = 0, x = 0, b = 20 mm
    geo0 = CylindricalPair.build(20, 40, 3e-3, an)
    q = 0.04723 + 0.15551 / 20 + 0.25791 / 40
    c_ref = 1.0 / q * 0.8 * 1.0 * 0.975 * (0.75 * geo0.eps_alpha + 0.25)
    iso = iso6336_mesh_stiffness(20, 40, 0.0, an, geo0.eps_alpha, 0.02)
    out.append(compare(case, "ISO 6336 c_gamma_alpha, 20/40, m 3, alpha 20, beta 0 (18.739)",
                       c_ref, iso.c_gamma_alpha_iso, "N/(mm um)", 1e-12,
                       "ISO 6336-1 method B by hand: q' = 0.061453, C_M 0.8, C_B 0.975, "
                       f"eps_alpha {geo0.eps_alpha:.5f}"))
    spec, geo = gear_pair_model(beta=beta, helix_angle_b=-beta)
    out.append(compare(case, "element default stiffness = ISO 6336 k_m (helical)",
                       iso6336_mesh_stiffness(20, 40, beta, an, geo.eps_alpha, 0.02).k_mesh,
                       mesh_info(dd.compile_model(spec), "g")["stiffness"], "N/m", 1e-12,
                       "ISO 6336-1 method B"))

    # natural frequency: free wheels, zero backlash, rho_inf = 1 (trapezoidal rule)
    spec, geo = gear_pair_model(beta=beta, helix_angle_b=-beta, stiffness=1e8)
    body = spec.bodies["A"]
    spec.bodies["A"] = type(body)(**{**body.__dict__, "angular_velocity": np.array([0, 0, 1.0])})
    m = dd.compile_model(spec)
    info = mesh_info(m, "g")
    w = float(np.sqrt(1e8 * (info["coef_a"] ** 2 / 2e-3 + info["coef_b"] ** 2 / 8e-3)))
    n_per = 200
    h = 2 * np.pi / w / n_per
    periods = 20 if quick else 40
    res = dd.simulate(m, periods * 2 * np.pi / w, step=dd.FixedStep(h),
                      integrator=dd.GeneralizedAlpha(1.0), output_dt=h)
    q1 = "mesh natural frequency sqrt(k (c_A^2/J_A + c_B^2/J_B)), 200 steps per period"
    src = "two inertias coupled by the mesh, c = r_b cos(beta_b)"
    if not res.success:
        out.append(_failed(case, q1, "rad/s", 2e-4, src, res))
    else:
        F = res["g.normal_force"].values
        tc = crossings(res.time, F - F.mean(), 1)
        w_sim = 2 * np.pi * (len(tc) - 1) / (tc[-1] - tc[0])
        # the trapezoidal rule shortens the frequency by (w h)^2 / 12 = 8.2e-5 here
        out.append(compare(case, q1, w, w_sim, "rad/s", 2e-4, src))
        out.append(compare(case, "mesh natural frequency, trapezoidal dispersion removed "
                           "(2/h) atan(w h/2)", 2 / h * np.arctan(0.5 * w * h), w_sim, "rad/s",
                           1e-5, src))

    # kinematic ratio over 120 revolutions, external helical pair, loaded
    za, zb = 17, 43
    spec, geo = gear_pair_model(za, zb, beta=np.radians(15.0), helix_angle_b=-np.radians(15.0),
                                stiffness=2e8, damping_ratio=0.05)
    revs = 30 if quick else 120
    spec.add(dd.JointDriver("drive", "hA", dd.SmoothStep(0.0, 0.05, 0.0, 2 * np.pi * 100),
                            quantity="speed"))
    spec.add(dd.Torque("load", "mB", vector=(0.0, 0.0, -5.0)))
    res = dd.simulate(dd.compile_model(spec), 0.025 + revs / 100.0 + 0.005,
                      step=dd.FixedStep(2e-4), integrator=dd.GeneralizedAlpha(0.9),
                      output_dt=5e-3)
    q2 = f"speed ratio -z_B/z_A x angle B / angle A after {revs} revolutions"
    if not res.success:
        out.append(_failed(case, q2, "1", 1e-6, "gear kinematics", res))
    else:
        ratio = res["hB.angle"].values[-1] / res["hA.angle"].values[-1]
        # the mesh deflection (5 N m load) changes angle B by u / c_B ~ 1e-7 rad
        out.append(compare(case, q2, 1.0, -ratio * zb / za, "1", 1e-6,
                           "z_A/z_B, 17/43 helical, 100 rev/s"))

    # worm efficiency with tooth friction (mu 0.05, lead angle 10 deg, 2 starts / 40 teeth)
    mu, gam = 0.05, np.radians(10.0)
    bA, bB = np.pi / 2 - gam, gam
    rA, rB = 2 * 3e-3 / (2 * np.cos(bA)), 40 * 3e-3 / (2 * np.cos(bB))
    c, s = np.cos(-(bA + bB)), np.sin(-(bA + bB))
    FB = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    spec = dd.Spec()
    spec.add_rigid_body("worm", 0.5, (1e-4, 1e-4, 1e-4))
    spec.add_rigid_body("wheel", 2.0, (5e-3, 5e-3, 5e-3), position=(rA + rB, 0, 0))
    spec.add_marker("g1", "ground", axis=GEAR_Z)
    spec.add_marker("m1", "worm", axis=GEAR_Z)
    spec.add_marker("g2", "ground", position=(rA + rB, 0, 0), rotation=FB)
    spec.add_marker("m2", "wheel", rotation=FB)
    spec.add(dd.Hinge("h1", "g1", "m1"))
    spec.add(dd.Hinge("h2", "g2", "m2"))
    spec.add(dd.GearPair("w", "m1", "m2", 2, 40, 3e-3, 0.02, helix_angle=bA, helix_angle_b=bB,
                         kind="crossed", stiffness=1e8, damping=500.0, friction=mu))
    spec.add(dd.JointDriver("drive", "h1", dd.SmoothStep(0, 0.02, 0, 100.0), quantity="speed"))
    spec.add(dd.Torque("load", "m2", vector=20.0 * FB[:, 2]))
    res = dd.simulate(dd.compile_model(spec), 0.1, step=dd.FixedStep(2e-5),
                      integrator=dd.GeneralizedAlpha(0.9), output_dt=1e-3)
    q3 = "worm efficiency, mu 0.05, lead angle 10 deg"
    src = "tan(gamma) / tan(gamma + phi'), tan(phi') = mu / cos(alpha_n) (worm driving)"
    phi = np.arctan(mu / np.cos(an))
    if not res.success:
        out.append(_failed(case, q3, "1", 1e-5, src, res))
    else:
        wB = float(res["wheel.angular_velocity"].values[-1] @ FB[:, 2])
        eta = 20.0 * abs(wB) / float(res["drive.power"].values[-1])
        out.append(compare(case, q3, np.tan(gam) / np.tan(gam + phi), eta, "1", 1e-5, src))
    return _finish(out, t0, [])


@register_case("planetary_set")
def planetary_set(quick: bool = False, figure_dir: str | None = None) -> list[CaseResult]:
    """Helical planetary set (sun 24, three planets 18, ring 60): Willis equation with sun and
    ring driven, static torque split with carrier and ring held."""
    t0 = time.perf_counter()
    case = "planetary_set"
    zs, zp, zr, mn, beta = 24, 18, 60, 2e-3, np.radians(15.0)

    def build() -> dd.Spec:
        rs, rp = zs * mn / (2 * np.cos(beta)), zp * mn / (2 * np.cos(beta))
        spec = dd.Spec()
        spec.add_rigid_body("sun", 1.0, (1e-3, 1e-3, 1.5e-3))
        spec.add_rigid_body("ring", 3.0, (2e-2, 2e-2, 3e-2))
        spec.add_rigid_body("carrier", 2.0, (5e-3, 5e-3, 8e-3))
        for name in ("sun", "ring", "carrier"):
            spec.add_marker(f"g_{name}", "ground", axis=GEAR_Z)
            spec.add_marker(f"m_{name}", name, axis=GEAR_Z)
            spec.add(dd.Hinge(f"h_{name}", f"g_{name}", f"m_{name}"))
        for k in range(3):
            ang = 2 * np.pi * k / 3
            pos = (rs + rp) * np.array([np.cos(ang), np.sin(ang), 0.0])
            spec.add_rigid_body(f"planet{k}", 0.3, (1e-4, 1e-4, 1.5e-4), position=pos)
            spec.add_marker(f"c{k}", "carrier", position=pos, axis=GEAR_Z)
            spec.add_marker(f"p{k}", f"planet{k}", axis=GEAR_Z)
            spec.add(dd.Hinge(f"hp{k}", f"c{k}", f"p{k}"))
            spec.add(dd.GearPair(f"sp{k}", "m_sun", f"p{k}", zs, zp, mn, 0.015,
                                 helix_angle=beta, damping_ratio=0.05))
            spec.add(dd.GearPair(f"pr{k}", f"p{k}", "m_ring", zp, zr, mn, 0.015,
                                 helix_angle=-beta, internal="b", damping_ratio=0.05))
        return spec

    out: list[CaseResult] = []
    spec = build()
    ws, wr = 30.0, -5.0
    spec.add(dd.JointDriver("d_s", "h_sun", dd.SmoothStep(0, 0.05, 0, ws), quantity="speed"))
    spec.add(dd.JointDriver("d_r", "h_ring", dd.SmoothStep(0, 0.05, 0, wr), quantity="speed"))
    res = dd.simulate(dd.compile_model(spec), 0.15 if quick else 0.3, step=dd.FixedStep(1e-4),
                      integrator=dd.GeneralizedAlpha(0.9), output_dt=1e-3)
    q = "carrier speed, sun 30 rad/s, ring -5 rad/s"
    src = "Willis: w_c = (z_S w_s + z_R w_r) / (z_S + z_R)"
    if not res.success:
        out.append(_failed(case, q, "rad/s", 1e-7, src, res))
    else:
        wc = float(res["carrier.angular_velocity"].values[-1, 2])
        out.append(compare(case, q, (zs * ws + zr * wr) / (zs + zr), wc, "rad/s", 1e-7, src))
        wp = float(res["planet0.angular_velocity"].values[-1, 2])
        out.append(compare(case, "planet speed relative to the carrier / (w_s - w_c)", -zs / zp,
                           (wp - wc) / (ws - wc), "1", 1e-7, "Willis: -z_S / z_P"))
    spec = build()
    spec.add(dd.JointDriver("hold_c", "h_carrier", 0.0, quantity="angle"))
    spec.add(dd.JointDriver("hold_r", "h_ring", 0.0, quantity="angle"))
    spec.add(dd.Torque("Ts", "m_sun", vector=(0, 0, 30.0)))
    m = dd.compile_model(spec)
    o = dd.element_outputs(m, dd.solve_static(m))
    t_ring = abs(sum(o[f"pr{k}"]["torque_b"] for k in range(3)))
    out.append(compare(case, "static torque split T_ring / T_sun (no friction)", zr / zs,
                       t_ring / 30.0, "1", 1e-9, "moment balance of the planets: z_R / z_S"))
    loads = [o[f"sp{k}"]["normal_force"] for k in range(3)]
    out.append(compare(case, "load sharing: spread of the three sun-planet forces / mean", 0.0,
                       float(np.ptp(loads) / np.mean(loads)), "1", 1e-9, "symmetry"))
    return _finish(out, t0, [])


# the TORSEN cases live in their own module; importing it registers them
from drivedyn.validation import torsen_cases  # noqa: E402, F401
