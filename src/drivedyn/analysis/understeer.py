"""Understeer gradient of the RWD vehicle: measured on the 3-D model in a steady circle, and
the single-track (bicycle) reference with the effects that make the 3-D vehicle differ from
it, each declared and quantified.

Steady state, left turn, yaw rate ``r`` and speed ``V`` of the centre of gravity, lateral
acceleration ``a_y = V r``, path radius ``R = V / r``, wheelbase ``L``, road-wheel steer
``delta`` (the pinion angle times the steering ratio measured on the model's kinematics):
``delta = L / R + K a_y`` defines the understeer gradient ``K`` [rad/(m/s^2)]
(ISO 4138; :func:`measured_gradient`).

The reference (:func:`reference_gradient`) starts from the linear single-track model:
axle cornering stiffnesses ``C_f, C_r`` [N/rad], the sums of the Magic Formula's
``-dFy/dalpha`` at ``alpha = 0`` (no camber, no slip) at each wheel's static load, and the
static axle masses ``m_f = m b / L``, ``m_r = m a / L`` (``a``, ``b`` the centre of gravity's
distances from the front and rear axles): ``K_0 = m_f / C_f - m_r / C_r``. The axles'
slip angles then satisfy, in steady state, ``alpha_f - alpha_r = delta - L / R`` and
``K = (alpha_f - alpha_r) / a_y``.

The 3-D vehicle differs from it by the effects below. Each is measured on the model (the
parked vehicle's static solutions under the steady-state loads, see
:func:`quasi_static_state`) or taken from the tyre model, and the reference includes them
one after the other, in this order (each term is the change of ``K`` when its effect is
added to the ones before; :data:`TERMS`):

1. ``tyre curve``: the Magic Formula's lateral force at the finite slip angle instead of
   ``C alpha``;
2. ``load transfer``: each wheel's load under the cornering loads (lateral load transfer,
   and the longitudinal one of the drive torque's reaction on the frame and of the
   longitudinal acceleration), with the cornering stiffness's dependence on the load;
3. ``static alignment``: each wheel's toe, camber and the steering's Ackermann at the
   ride height, with the steer;
4. ``roll and compliance steer``: the change of each wheel's steer angle under the
   cornering loads (suspension kinematics in roll, bushings under the tyres' forces and
   aligning moments; :func:`steer_split` separates the roll steer, measured under a pure
   roll moment, from the rest);
5. ``camber change``: the change of each wheel's camber under the cornering loads;
6. ``aligning moments``: the tyres' aligning moments in the yaw balance;
7. ``longitudinal forces``: rolling resistance (the tyre model's ``My``) and the drive
   force (the open differential's equal torques on the rear wheels, their sum from the
   longitudinal balance) in the balances: with the loads transferred across the axle they
   yaw the vehicle; and the longitudinal slips these forces take, which change the lateral
   forces (combined slip).

The cornering loads applied to the parked vehicle (front brakes, ground bushing in plane;
:func:`~drivedyn.library.vehicles.vehicle_rwd.model.build_spec`) are the steady state's:
d'Alembert's inertial loads of every mass (gravity tilted by ``-a_y`` sideways and
``-a_x`` lengthways: ``a_x = -v_y r``, the centre of gravity's acceleration along the
vehicle in a steady turn), the tyres' lateral forces at the contact points and their
aligning moments, their longitudinal forces at the wheel centres (the wheel's torque goes
to the half-shaft or nowhere), the drive torques' reaction on the rear carrier, the
spinning wheels' gyroscopic moments (``J omega r`` about x) and the lifts that cancel the
weight of the differential's gears as in the rolling vehicle. The tyres' forces come from
the reference's own solution, so the parked solution and the reference are iterated
(:data:`ITERATIONS`). Not included (each below 1 % of ``K``, estimated): the track's
effect on each wheel's slip angle (``y r / V``), the centripetal field's variation over the
vehicle (``r^2``), the yaw-rate terms of the rotating driveline (pitch only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import root

from drivedyn.elements import Force, Torque
from drivedyn.errors import ModelError
from drivedyn.library.vehicles.vehicle_rwd.model import CARRIED, G, Layout, build_spec, load_tyre
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS, VehicleRWDFile
from drivedyn.tyres import Tyre

#: passes of parked solution and reference (the third changes K by less than 0.1 %)
ITERATIONS = 3
#: the reference's terms in the order they are added (see the module docstring)
TERMS = ("linear single-track", "tyre curve", "load transfer", "static alignment",
         "roll and compliance steer", "camber change", "aligning moments",
         "longitudinal forces")
FRONT, REAR = ("fl", "fr"), ("rl", "rr")
#: Newton steps on a wheel's longitudinal slip for its longitudinal force (the slip
#: stiffness at zero slip as the derivative; 1e-4 N after three)
KAPPA_ITERATIONS = 3
#: pure roll moment [N m] of the roll-steer solution (about the steady circle's at 0.2 g)
ROLL_MOMENT = 2000.0


@dataclass
class WheelState:
    """A wheel of the parked vehicle's static solution: steer (heading from the vehicle's x
    axis, left positive) and camber (tyre convention: top towards the tyre's +y) [rad],
    vertical load [N], centre x, y [m] and its height above the road [m]."""

    steer: float
    camber: float
    fz: float
    x: float
    y: float
    height: float


@dataclass
class Loads:
    """The steady state's loads on the parked vehicle (see the module docstring): lateral
    and longitudinal accelerations [m/s^2], per wheel lateral force [N] (along the wheel's
    y), aligning moment [N m], longitudinal force [N] (along its heading, at the centre),
    gyroscopic moment about x [N m]; ``drive``: the drive torque on each rear wheel
    [N m]; ``roll_moment``: a pure roll moment about x [N m] on the body (vertical forces
    on its carriers; for the roll steer, :func:`steer_split`)."""

    ay: float = 0.0
    ax: float = 0.0
    fy: dict[str, float] = field(default_factory=lambda: dict.fromkeys(WHEELS, 0.0))
    mz: dict[str, float] = field(default_factory=lambda: dict.fromkeys(WHEELS, 0.0))
    fx: dict[str, float] = field(default_factory=lambda: dict.fromkeys(WHEELS, 0.0))
    gyro: float = 0.0
    drive: float = 0.0
    roll_moment: float = 0.0


@dataclass
class Parked:
    """A static solution of the parked vehicle: the wheels' states, the frame's roll angle
    [rad] (about x, left side up positive; at the node of the speed sensor) and the
    layout."""

    wheels: dict[str, WheelState]
    roll: float
    layout: Layout


def _parked(p: VehicleRWDFile) -> VehicleRWDFile:
    """``p`` at rest, engine off."""
    return p.model_copy(update={"engine": p.engine.model_copy(update={"throttle": 0.0}),
                                "body": p.body.model_copy(update={"speed": 0.0})})


def quasi_static_state(p: VehicleRWDFile, torsen: dict, base_dir: str | Path, theta: float,
                       loads: Loads | None = None) -> Parked:
    """The parked vehicle's static solution with the pinion at ``theta`` [rad] under
    ``loads`` (None: gravity only)."""
    from drivedyn.library.vehicles.vehicle_rwd.cornering import sensor_node
    from drivedyn.model.compile import compile_model
    from drivedyn.solver.statics import solve_static
    from drivedyn.solver.system import element_outputs

    ld = loads or Loads()
    sp, lay = build_spec(_parked(p), torsen, base_dir, parked=True, steer=theta)
    sp.settings.gravity = np.array([-ld.ax, -ld.ay, -G])
    for name, bd in list(sp.bodies.items()):  # as the rolling vehicle: gears lifted
        if name.startswith("rear_") and name.split("_", 1)[1] not in CARRIED:
            sp.add_marker(f"{name}_cg", name, position=bd.com)
            sp.add(Force(f"{name}_lift", f"{name}_cg", vector=(0.0, 0.0, G * bd.mass)))
    for w in WHEELS:
        wb = lay.wheels[w]
        bd = sp.bodies[wb]
        contact = bd.position * np.array([1.0, 1.0, 0.0])
        # markers with the global axes at t = 0: they steer and camber with the wheel
        sp.add_marker(f"contact_{w}", wb, position=bd.rotation.T @ (contact - bd.position),
                      rotation=bd.rotation.T)
        sp.add_marker(f"centre_{w}", wb, rotation=bd.rotation.T)
        if loads is None:
            continue
        sp.add(Force(f"fy_{w}", f"contact_{w}", vector=(0.0, ld.fy[w], 0.0), frame="marker"))
        sp.add(Torque(f"mz_{w}", f"contact_{w}", vector=(0.0, 0.0, ld.mz[w]), frame="marker"))
        sp.add(Force(f"fx_{w}", f"centre_{w}", vector=(ld.fx[w], 0.0, 0.0), frame="marker"))
        sp.add(Torque(f"gyro_{w}", f"centre_{w}", vector=(ld.gyro, 0.0, 0.0)))
    if loads is not None and ld.drive:
        sp.add_marker("carrier_drive", "carrier")
        sp.add(Torque("drive_reaction", "carrier_drive", vector=(0.0, -2.0 * ld.drive, 0.0)))
    if ld.roll_moment:
        carriers = [n for n in sp.bodies if n.startswith("frame.body.")]
        arm = sum(abs(sp.bodies[n].position[1]) for n in carriers)
        for n in carriers:
            side = math.copysign(1.0, sp.bodies[n].position[1])
            sp.add_marker(f"{n}.roll", n)
            sp.add(Force(f"{n}.roll", f"{n}.roll", vector=(0.0, 0.0,
                                                            side * ld.roll_moment / arm)))
    node = sensor_node(sp, lay.cg)
    model = compile_model(sp)
    st = solve_static(model, max_iter=100)
    out = element_outputs(model, st)
    wheels = {}
    for w in WHEELS:
        j = model.node_index[lay.wheels[w]]
        a = st.R[j][:, 2]  # spin axis, to the wheel's left
        ty = out[lay.tyres[w]]
        wheels[w] = WheelState(steer=float(math.atan2(-a[0], a[1])), camber=ty["camber"],
                               fz=ty["fz"], x=float(st.x[j][0]), y=float(st.x[j][1]),
                               height=ty["height"])
    j = model.node_index[node]
    Q = st.R[j] @ sp.nodes[node].rotation.T
    return Parked(wheels, float(math.atan2(Q[2, 1], Q[2, 2])), lay)


@dataclass
class Inputs:
    """What the reference's axle equations read (see :func:`solve_axles`): the mass [kg]
    and centre of gravity x [m], the nominal road-wheel steer [rad], the speed [m/s], the
    wheels' states (loads, steer, camber, positions), their tyres, and the switches of the
    terms."""

    mass: float
    x_cg: float
    delta: float
    speed: float
    wheels: dict[str, WheelState]
    tyres: dict[str, Tyre]
    curve: bool = True
    mz: bool = True
    fx: bool = True


@dataclass
class Solution:
    """The axles' slip angles [rad] (positive: a force to the left) and the wheels' forces
    of the reference at one lateral acceleration: per wheel ``fy``, ``fx`` [N], ``mz``
    [N m], longitudinal slip ``kappa``; the drive torque per rear wheel [N m]; the
    longitudinal acceleration [m/s^2]."""

    alpha_f: float
    alpha_r: float
    fy: dict[str, float]
    fx: dict[str, float]
    mz: dict[str, float]
    kappa: dict[str, float]
    drive: float
    ax: float


def _cornering_stiffness(tyre: Tyre, fz: float, speed: float) -> float:
    """``-dFy/dalpha`` [N/rad] at ``alpha = 0``, no slip, no camber (central difference)."""
    e = 1e-6
    fp = float(tyre.forces(fz=fz, kappa=0.0, alpha=e, vx=speed)[1])
    fm = float(tyre.forces(fz=fz, kappa=0.0, alpha=-e, vx=speed)[1])
    return -(fp - fm) / (2.0 * e)


def solve_axles(inp: Inputs, ay: float) -> Solution:
    """The axle slip angles that balance the vehicle at ``ay`` [m/s^2] (lateral and yaw
    balances; the longitudinal one gives the drive torque), each wheel's slip angle being
    its axle's plus its steer's offset from the nominal (``delta`` at the front, 0 at the
    rear)."""
    W = inp.wheels
    m, V = inp.mass, inp.speed
    r = ay / V
    xr = 0.5 * (W["rl"].x + W["rr"].x)
    b = inp.x_cg - xr
    stiff = {w: _cornering_stiffness(inp.tyres[w], W[w].fz, V) for w in WHEELS}

    def wheel(w: str, alpha: float, fx: float | None = None
              ) -> tuple[float, float, float, float]:
        """(fy, mz, |my|, kappa) of wheel ``w`` at its axle's slip angle ``alpha``; with
        ``fx`` the longitudinal slip that gives that longitudinal force."""
        nominal = inp.delta if w in FRONT else 0.0
        a = alpha + W[w].steer - nominal
        if not inp.curve:
            return stiff[w] * a, 0.0, 0.0, 0.0
        ty, kappa = inp.tyres[w], 0.0
        e = ty.evaluate(fz=W[w].fz, kappa=0.0, alpha=-a, gamma=W[w].camber, vx=V)
        for _ in range(KAPPA_ITERATIONS if fx is not None else 0):
            kappa += (fx - float(e["fx"])) / float(e["kxk"])
            e = ty.evaluate(fz=W[w].fz, kappa=kappa, alpha=-a, gamma=W[w].camber, vx=V)
        return float(e["fy"]), float(e["mz"]), abs(float(e["my"])), kappa

    def forces(x: np.ndarray) -> tuple[dict, dict, dict, dict, float, float]:
        fy, mz, fx, kappa, rolling = {}, {}, {}, dict.fromkeys(WHEELS, 0.0), {}
        alpha = {w: x[0] if w in FRONT else x[1] for w in WHEELS}
        for w in WHEELS:
            fy[w], mz[w], my, _ = wheel(w, alpha[w])
            rolling[w] = my / W[w].height
        ax = -(b * r - V * x[1]) * r  # a_x = -v_y r, v_y = b r - V alpha_r
        drive = 0.0
        for w in WHEELS:
            fx[w] = -rolling[w] if inp.fx else 0.0
        if inp.fx:
            # longitudinal balance: sum (fx cos s - fy sin s) = m a_x, rear fx = T/h - rolling
            need = m * ax + sum(fy[w] * math.sin(W[w].steer) for w in WHEELS) \
                - sum(fx[w] * math.cos(W[w].steer) for w in FRONT)
            drive = (need + sum(rolling[w] * math.cos(W[w].steer) for w in REAR)) / sum(
                math.cos(W[w].steer) / W[w].height for w in REAR)
            for w in REAR:
                fx[w] = drive / W[w].height - rolling[w]
            # the slips these forces take, and the lateral forces with them (combined slip)
            for w in WHEELS:
                fy[w], mz[w], _, kappa[w] = wheel(w, alpha[w], fx[w])
        if not inp.mz:
            mz = dict.fromkeys(WHEELS, 0.0)
        return fy, mz, fx, kappa, drive, ax

    def residual(x: np.ndarray) -> np.ndarray:
        fy, mz, fx, _, _, _ = forces(x)
        Y = N = 0.0
        for w in WHEELS:
            c, s = math.cos(W[w].steer), math.sin(W[w].steer)
            lat = fy[w] * c + fx[w] * s
            lon = fx[w] * c - fy[w] * s
            Y += lat
            N += (W[w].x - inp.x_cg) * lat - W[w].y * lon + mz[w]
        return np.array([(Y - m * ay) / (m * G), N / (m * G)])

    x0 = np.array([1.0, 1.0]) * ay * m / sum(stiff.values())
    sol = root(residual, x0, method="hybr", options={"xtol": 1e-12})
    # judged by the residual (relative to the weight): the solver's own stop may be
    # round-off stagnation
    if np.max(np.abs(residual(sol.x))) > 1e-10:
        raise ModelError(f"understeer reference: no axle balance at a_y = {ay:g} m/s^2 "
                         f"({sol.message})")
    fy, mz, fx, kappa, drive, ax = forces(sol.x)
    return Solution(float(sol.x[0]), float(sol.x[1]), fy, fx, mz, kappa, float(drive),
                    float(ax))


@dataclass
class Reference:
    """The reference understeer gradient and its terms.

    Attributes:
        gradient: ``K`` of the reference with every term [rad/(m/s^2)].
        terms: (name, contribution [rad/(m/s^2)]) in :data:`TERMS` order; the first is the
            linear single-track ``K_0``, the others the changes (they sum to ``gradient``).
        ay: lateral acceleration [m/s^2]; speed [m/s]; theta: pinion angle [rad].
        ratio: road-wheel steer per pinion angle [rad/rad] (mean of the front wheels, from
            the parked vehicle's static solutions at 0 and ``theta``); delta [rad].
        wheelbase: [m]; a, b: the centre of gravity from the front and rear axles [m];
            x_cg: its x [m].
        mass: [kg]; m_f, m_r: static axle masses [kg]; c_f, c_r: axle cornering
            stiffnesses [N/rad] at the static loads.
        static, loaded: the wheels' states at rest (steered) and under the cornering loads.
        solution: the full reference's :class:`Solution`.
        tyres: the wheels' tyres (as the reference used them).
        roll_static, roll_loaded: the frame's roll angle at rest and under the loads [rad].
        solves: static solutions computed.
    """

    gradient: float
    terms: list[tuple[str, float]]
    ay: float
    speed: float
    theta: float
    ratio: float
    delta: float
    wheelbase: float
    a: float
    b: float
    x_cg: float
    mass: float
    m_f: float
    m_r: float
    c_f: float
    c_r: float
    static: dict[str, WheelState]
    loaded: dict[str, WheelState]
    solution: Solution
    tyres: dict[str, Tyre] = field(default_factory=dict)
    roll_static: float = 0.0
    roll_loaded: float = 0.0
    solves: int = 0


def _mix(fz: dict[str, WheelState], steer: dict[str, WheelState],
         camber: dict[str, WheelState]) -> dict[str, WheelState]:
    """Wheel states with the loads (and positions) of ``fz``, the steer of ``steer`` and
    the camber of ``camber``."""
    return {w: WheelState(steer[w].steer, camber[w].camber, fz[w].fz, fz[w].x, fz[w].y,
                          fz[w].height) for w in WHEELS}


def steering_ratio(zero: dict[str, WheelState], steered: dict[str, WheelState],
                   theta: float) -> float:
    """Road-wheel steer per pinion angle [rad/rad]: the front wheels' mean steer change
    from ``zero`` to ``steered`` over ``theta``."""
    return float(np.mean([(steered[w].steer - zero[w].steer) / theta for w in FRONT]))


def reference_gradient(p: VehicleRWDFile, torsen: dict, base_dir: str | Path, theta: float,
                       speed: float, ay: float, rear_stiffness: float = 1.0,
                       iterations: int = ITERATIONS) -> Reference:
    """The reference understeer gradient at lateral acceleration ``ay`` [m/s^2] and
    ``speed`` [m/s] with the pinion at ``theta`` [rad] (see the module docstring).
    ``rear_stiffness`` scales the rear tyres' cornering stiffness in the reference (1: the
    tyres as they are; 2: the mutation that makes the validation fail)."""
    if theta == 0.0:
        raise ModelError("understeer reference: theta = 0 rad gives no steering ratio")
    tyres = {w: load_tyre(p, base_dir, "left" if w[1] == "l" else "right") for w in WHEELS}
    if rear_stiffness != 1.0:
        for w in REAR:
            tyres[w] = tyres[w].scaled(LKY=rear_stiffness)
    zero_p = quasi_static_state(p, torsen, base_dir, 0.0)
    static_p = quasi_static_state(p, torsen, base_dir, theta)
    zero, static, lay = zero_p.wheels, static_p.wheels, zero_p.layout
    ratio = steering_ratio(zero, static, theta)
    delta = ratio * theta
    m, x_cg = lay.total_mass, float(lay.cg[0])
    xf = 0.5 * (static["fl"].x + static["fr"].x)
    xr = 0.5 * (static["rl"].x + static["rr"].x)
    L = xf - xr
    a, b = xf - x_cg, x_cg - xr
    m_f, m_r = m * b / L, m * a / L
    c = {w: _cornering_stiffness(tyres[w], zero[w].fz, speed) for w in WHEELS}
    c_f, c_r = c["fl"] + c["fr"], c["rl"] + c["rr"]
    k0 = m_f / c_f - m_r / c_r
    # the parked vehicle under the reference's loads, iterated
    omega = speed / lay.rolling_radius
    J = p.wheels.inertia[1] if np.ndim(p.wheels.inertia) == 1 else np.asarray(
        p.wheels.inertia)[1, 1]
    r = ay / speed
    base = Inputs(m, x_cg, delta, speed, static, tyres)
    sol = solve_axles(base, ay)
    loaded_p = static_p
    for _ in range(iterations):
        loads = Loads(ay=ay, ax=sol.ax, fy=sol.fy, mz=sol.mz, fx=sol.fx, gyro=J * omega * r,
                      drive=sol.drive)
        loaded_p = quasi_static_state(p, torsen, base_dir, theta, loads)
        sol = solve_axles(Inputs(m, x_cg, delta, speed, loaded_p.wheels, tyres), ay)
    loaded = loaded_p.wheels
    # the terms, added one after the other
    # at rest: no steer offsets (the front wheels at the nominal steer), no camber
    rest = {w: WheelState(delta if w in FRONT else 0.0, 0.0, zero[w].fz, static[w].x,
                          static[w].y, static[w].height) for w in WHEELS}

    steps = [
        Inputs(m, x_cg, delta, speed, rest, tyres, mz=False, fx=False),
        Inputs(m, x_cg, delta, speed, _mix(loaded, rest, rest), tyres, mz=False, fx=False),
        Inputs(m, x_cg, delta, speed, _mix(loaded, static, static), tyres, mz=False,
               fx=False),
        Inputs(m, x_cg, delta, speed, _mix(loaded, loaded, static), tyres, mz=False,
               fx=False),
        Inputs(m, x_cg, delta, speed, loaded, tyres, mz=False, fx=False),
        Inputs(m, x_cg, delta, speed, loaded, tyres, fx=False),
        Inputs(m, x_cg, delta, speed, loaded, tyres),
    ]
    gradients = [k0]
    for inp in steps:
        s = solve_axles(inp, ay)
        gradients.append((s.alpha_f - s.alpha_r) / ay)
    terms = [(TERMS[0], k0)] + [(TERMS[i], gradients[i] - gradients[i - 1])
                                for i in range(1, len(TERMS))]
    return Reference(gradient=gradients[-1], terms=terms, ay=ay, speed=speed, theta=theta,
                     ratio=ratio, delta=delta, wheelbase=L, a=a, b=b, x_cg=x_cg, mass=m, m_f=m_f,
                     m_r=m_r, c_f=c_f, c_r=c_r, static=static, loaded=loaded, solution=sol,
                     tyres=tyres, roll_static=static_p.roll, roll_loaded=loaded_p.roll,
                     solves=2 + iterations)


@dataclass
class SteerSplit:
    """The ``roll and compliance steer`` term split: per wheel the steer per roll angle
    under a pure roll moment [rad/rad] (the roll steer), the frame's roll under the
    cornering loads [rad], the kinematic roll steer there [rad], and the term's shares
    [rad/(m/s^2)]: the roll steer's (the reference with only it added to the static
    alignment) and the rest's (compliance steer: the bushings under the tyres' forces and
    moments)."""

    coefficient: dict[str, float]
    roll: float
    steer: dict[str, float]
    roll_steer: float
    compliance_steer: float


def steer_split(p: VehicleRWDFile, torsen: dict, base_dir: str | Path, ref: Reference,
                moment: float = ROLL_MOMENT) -> SteerSplit:
    """:class:`SteerSplit` of ``ref`` (one more static solution: the parked vehicle with
    ``moment`` [N m] of pure roll on its body, the pinion at ``ref.theta``)."""
    rolled = quasi_static_state(p, torsen, base_dir, ref.theta, Loads(roll_moment=moment))
    d_roll = rolled.roll - ref.roll_static
    coef = {w: (rolled.wheels[w].steer - ref.static[w].steer) / d_roll for w in WHEELS}
    roll = ref.roll_loaded - ref.roll_static
    kin = {w: WheelState(ref.static[w].steer + coef[w] * roll, 0.0, 0.0, 0.0, 0.0, 0.0)
           for w in WHEELS}
    args = (ref.mass, ref.x_cg, ref.delta, ref.speed)
    k = []
    for steer in (ref.static, kin):
        s = solve_axles(Inputs(*args, _mix(ref.loaded, steer, ref.static), ref.tyres, mz=False,
                               fx=False), ref.ay)
        k.append((s.alpha_f - s.alpha_r) / ref.ay)
    term = dict(ref.terms)[TERMS[4]]
    return SteerSplit(coef, roll, {w: coef[w] * roll for w in WHEELS}, k[1] - k[0],
                      term - (k[1] - k[0]))


@dataclass
class Measured:
    """The 3-D model's steady circle over a window: speed [m/s] and yaw rate [rad/s] (means),
    lateral acceleration ``V r`` [m/s^2], path radius ``V / r`` [m], the gradient ``(delta
    - L / R) / a_y`` [rad/(m/s^2)]."""

    speed: float
    yaw_rate: float
    ay: float
    radius: float
    gradient: float


def measured_gradient(speed: float, yaw_rate: float, delta: float,
                      wheelbase: float) -> Measured:
    """The understeer gradient of a steady circle at ``speed`` [m/s] and ``yaw_rate``
    [rad/s] with the road wheels at ``delta`` [rad] on ``wheelbase`` [m]."""
    ay = speed * yaw_rate
    R = speed / yaw_rate
    return Measured(speed, yaw_rate, ay, R, (delta - wheelbase / R) / ay)


def describe(ref: Reference) -> list[str]:
    """Lines naming each term of ``ref`` and its share [rad/(m/s^2)] and [deg/g]."""
    k = 180.0 / math.pi * G
    return [f"{name}: {v:+.4e} rad/(m/s^2) ({v * k:+.3f} deg/g)" for name, v in ref.terms]
