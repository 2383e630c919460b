"""Benchmark: the shaft chain, the gear chain and the flexible shaft, built and run in Exudyn.

The project's target is "drivedyn's wall <= 0.25 of Exudyn's wall on the same run". This
script builds the runs of ``shaft_chain.py``, ``gear_chain.py`` (fixed step) and
``flexible_shaft.py`` in Exudyn (https://github.com/jgerstmayr/EXUDYN) with the same
parameters, integrator family and outputs, times them, and with ``--drivedyn`` runs drivedyn's
own timed function of the same run in the same process. The parameters are read from those
three scripts (their module constants, the section's properties from drivedyn's
``HollowCircular.properties``), so both sides always model the same thing.

Races (Exudyn side; the figures in parentheses are drivedyn's at the default sizes, 1 s):

* ``shaft``: N 3-D rigid bodies (``ObjectRigidBody`` on ``NodeRigidBodyRxyz``: 6
  coordinates and no normalisation constraint, as drivedyn's 6 dofs per body) on
  ``ObjectJointRevoluteZ`` joints to the ground, their z axis turned onto global x by the
  markers' ``localHT``; neighbours coupled by ``ObjectConnectorTorsionalSpringDamper``
  (1e4 N m/rad, 1 N m s/rad), 100 N m (``LoadTorqueVector``) on disk 1, a torsional damper
  (1 N m s/rad, no stiffness) from the last disk to the ground. 11 N unknowns on both sides
  (6 coordinates and 5 joint multipliers per disk). Prints ``omega_last``, the last disk's
  speed about x at the end (N = 200: 99.46955 rad/s).
* ``gear``: Exudyn has no gear element. The row is the rigid bodies and revolute joints of
  ``shaft``, each mesh a linear spring-damper on the two hinge angles: an
  ``ObjectGenericODE2`` on the two nodes whose stiffness and damping matrices hold only the
  mesh's torsional equivalent along the line of action, ``k_m r_b^2`` = 1e8 N/m x
  (0.05 m cos 20 deg)^2 = 2.2076e5 N m/rad and ``c_m r_b^2`` = 1e3 N s/m x r_b^2 =
  2.2076 N m s/rad (r_b: the base radius at ``GearPair``'s default pressure angle of
  20 deg), on ``theta_a + theta_b``: the external mesh, alternate gears turning in opposite
  directions. The model is drivedyn's turned by the rotation z -> x, x -> y (hinge axes
  along x, centres along y; no gravity), so that the hinge angle is the nodes' first
  Tait-Bryan angle, on which the joints' Jacobian does not depend. (About z, the third
  angle, the iteration matrix turns with the gears: N = 50, 0.3 s took 6821 Newton
  iterations and 421 Jacobians instead of 3000 and 1. ``CoordinateSpringDamperExt`` with
  ``factor0 = -1`` made the solver cut the step fourfold and moved the speed by 6e-6
  relative: not used.) Not
  modelled: the radial mesh force (F_t tan 20 deg), which in drivedyn loads the hinges'
  translational rows and turns no gear. Prints ``omega_last``, the last gear's speed about
  its axis (N = 200: -99.31833 rad/s; the last gear of an even row turns against gear 1).
* ``beam``: ``ObjectBeamGeometricallyExact``, Exudyn's two-node shear-deformable beam
  interpolated on SE(3) (strain from the SE(3) logarithm of the relative node frames,
  constant along the element), the formulation of drivedyn's ``GeometricallyExactBeam``;
  ``ObjectANCFBeam`` is another one (absolute nodal coordinates with slope vectors and
  cross-section penalty terms). Nodes ``NodeRigidBodyRxyz``: the spin is the first
  Tait-Bryan angle, the second (singular at 90 deg) stays at the bending slope. The section
  is drivedyn's ``HollowCircular(0.040, 0.030)`` in ``STEEL`` (EA, Cowper's shear areas, GJ,
  EI; rho A, rho J_p, rho I), its mass lumped at the nodes as drivedyn's default
  (``exu.special.beams.geometricallyExactLumpedMass``, Exudyn's switch for comparisons;
  ``--beam-mass consistent`` for Exudyn's default). The element ignores the section's
  ``dampingMatrix``, so the material damping (5e-5 s) is a damper across each element
  (``ObjectConnectorRigidBodySpringDamper``, no stiffness) of beta GJ / L and beta EI / L on
  the relative angular velocity in the first node's frame: drivedyn's beta K_s epsdot on the
  twist and curvatures, to first order; the axial and shear strain rates are not damped (their
  modes lie far above the whirl). Left bearing ``ObjectJointRevoluteZ`` about x, right
  bearing ``ObjectJointGeneric`` free along and about x (a cylindrical joint), both holding
  the end slopes; the drive holds node 0's spin rate at 300 rad/s (``ObjectConnectorCoordinate``
  at velocity level; drivedyn's speed driver); the 0.1 kg unbalance a rigid body (1e-6 kg m^2)
  on a locked ``ObjectJointGeneric`` 50 mm off the axis at mid-span; gravity -z on the
  elements and the unbalance (``LoadMassProportional``). Everything starts turning rigidly at
  300 rad/s. Prints ``whirl_mm``, the mean mid-span distance from the axis over the second
  half of the run (100 elements: 0.2538 mm).

Solver (both sides): generalized-alpha, index-3 constraints, ``rho_inf`` of the drivedyn
script (0.9), fixed step h = 1e-4 s (a step whose Newton iteration fails is retried with
smaller steps on both sides), modified Newton. Exudyn: its Newton ``relativeTolerance`` at
1e-6 instead of its default 1e-8 (``--exudyn-rtol``; at 1e-8 the 100-element beam stalls at
the round-off floor of the residual from t = 8 ms on and the solver cuts the step to about
1e-6 s; the compared figures agree to 1e-7 between the two tolerances), its sparse LU
(``EigenSparse``; ``--linear-solver dense`` for ``EXUdense``), one thread. No solution file
(``solution.file.write = False``, the ``writeSolutionToFile`` of older releases), no
visualisation; one sensor per run stores the compared quantity in memory at the drivedyn
script's output interval (10 ms for the chains, 1 ms for the beam).

Wall times exclude building on both sides: ``exudyn_build_s`` is building the system and
``mbs.Assemble()``, ``exudyn_wall_s`` the ``mbs.SolveDynamic`` call (solver set-up, initial
accelerations, all steps); ``drivedyn_wall_s`` is the ``wall_s`` of the drivedyn script's
``run`` (``simulate`` only, after its warm-up of a few steps of the same size, as the script
does, so the numba kernels are compiled or loaded beforehand). Exudyn runs a few steps of
the same size first too.

Prints one JSON line per race and size: ``race``, ``N``, ``exudyn_wall_s``,
``exudyn_build_s``, ``steps``, ``newton_iterations``, ``jacobians`` (Exudyn's counts), the
physical figure (``omega_last`` or ``whirl_mm``), ``success``, ``exudyn_module``,
``exudyn_rtol``; with ``--drivedyn`` also ``drivedyn_wall_s``, ``ratio`` (=
drivedyn_wall_s / exudyn_wall_s), drivedyn's figure
(``drivedyn_omega_last`` / ``drivedyn_whirl_mm``), ``figure_rel_diff`` (Exudyn's figure over
drivedyn's minus 1) and drivedyn's ``drivedyn_steps``.

Usage::

    python benchmarks/exudyn_races.py                       # shaft, gear (N = 200), beam (100)
    python benchmarks/exudyn_races.py --drivedyn            # and drivedyn's run, the ratio
    python benchmarks/exudyn_races.py --runs shaft,gear --n 10 50 --t-end 0.5
    python benchmarks/exudyn_races.py --runs beam --beam-elements 20 --t-end 0.2 --drivedyn
    python benchmarks/exudyn_races.py --exudyn-fast          # Exudyn's exudynCPPfast module

Exudyn is optional (``pip install exudyn``, or ``pip install -e .[races]``; the EXUDYN
General License, BSD-3-clause terms). Without it the script says so on stderr and exits with
code 2 (no traceback).
``--exudyn-fast`` imports Exudyn's module without range checks (``sys.exudynFast = True``,
needs AVX2); the module used is in ``exudyn_module``. Written against Exudyn 1.13.6.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
import time

import flexible_shaft as fs
import gear_chain as gc
import numpy as np
import shaft_chain as sc

import drivedyn as dd

RACES = ("shaft", "gear", "beam")
BEAM_OUTPUT_DT = 1e-3  # [s] flexible_shaft.run's default output interval
GRAVITY = (0.0, 0.0, -9.81)  # [m/s^2] flexible_shaft's Spec(gravity=...)
UNBALANCE_INERTIA = 1e-6  # [kg m^2] flexible_shaft's unbalance body, about every axis
WARMUP_T = 5e-4  # [s] the Exudyn warm-up run: a few steps of the same size
# Exudyn's Newton tolerance relative to a step's initial residual (its default: 1e-8). At
# 1e-8 the 100-element beam stalls at the residual's round-off floor from t = 8 ms on (1.1e-5
# against a goal of 9.4e-6) and the solver cuts the step to about 1e-6 s; at 1e-6 all three
# races converge at the fixed step, their figures the same to 1e-7.
NEWTON_RTOL = 1e-6
# Ry(90 deg): its z axis is global x. Turns a joint's (or torsional spring's) z axis onto
# the shaft's and the chain's axis.
Z_ONTO_X = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
RXYZ_SIZE = 6  # coordinates of a NodeRigidBodyRxyz: position, then the Tait-Bryan angles
ANGLE_X = 3  # its first Tait-Bryan angle: the rotation about global x

exu = None  # the exudyn module, set by load_exudyn
ei = None  # exudyn.itemInterface


def load_exudyn(fast: bool) -> str:
    """Import Exudyn (its fast module if ``fast``); returns the compiled module's name.
    Exits with code 2 and a message if Exudyn is not installed."""
    global exu, ei
    if fast:
        sys.exudynFast = True
    try:
        # Exudyn announces its fast module on stdout, which carries the JSON lines
        with contextlib.redirect_stdout(sys.stderr):
            import exudyn
            import exudyn.itemInterface
    except ImportError as e:
        print(f"exudyn_races.py needs Exudyn, which is not installed ({e}).\n"
              "Install it with `pip install exudyn` (or `pip install -e .[races]`).",
              file=sys.stderr)
        raise SystemExit(2) from None
    exu, ei = exudyn, exudyn.itemInterface
    return "exudynCPPfast" if "exudyn.exudynCPPfast" in sys.modules else "exudynCPP"


def settings(t_end: float, h: float, rho_inf: float, output_dt: float, linear_solver: str,
             rtol: float = NEWTON_RTOL):
    """Fixed-step generalized-alpha of ``t_end`` [s], sensors every ``output_dt``, no files;
    ``rtol``: the Newton tolerance relative to the step's initial residual."""
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = t_end
    ti.numberOfSteps = max(1, round(t_end / h))
    ti.automaticStepSize = False
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = rho_inf
    ti.newton.relativeTolerance = rtol
    s.solution.file.write = False
    s.solution.sensors.writePeriod = output_dt
    s.linearSolver.solverType = (exu.LinearSolverType.EigenSparse if linear_solver == "sparse"
                                 else exu.LinearSolverType.EXUdense)
    s.show.computationTime = False
    s.show.statistics = False
    return s


def rigid_disk(mbs, position, mass: float, inertia: float) -> tuple[int, int]:
    """A rigid body at ``position``, inertia ``inertia`` about every axis; (node, body)."""
    node = mbs.AddNode(ei.NodeRigidBodyRxyz(referenceCoordinates=[*position, 0.0, 0.0, 0.0]))
    body = mbs.AddObject(ei.ObjectRigidBody(mass=mass, nodeNumber=node,
                                            inertia=[inertia] * 3 + [0.0] * 3))
    return node, body


def hinge(mbs, ground: int, body: int, position) -> int:
    """A revolute joint about global x of ``body`` to the ground at ``position``; returns
    the body's marker, whose z axis is the joint's."""
    mg = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=ground, localHT=exu.HT(
        rotation=Z_ONTO_X, translation=list(position))))
    mb = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=body, localHT=exu.HT(
        rotation=Z_ONTO_X, translation=[0.0, 0.0, 0.0])))
    mbs.AddObject(ei.ObjectJointRevoluteZ(markerNumbers=[mg, mb]))
    return mb


def mesh_stiffness() -> tuple[float, float]:
    """The gear mesh as a torsional spring-damper on the angles: (k_m r_b^2, c_m r_b^2)."""
    r_base = gc.TEETH * gc.MODULE / 2.0 * math.cos(dd.GearPair.pressure_angle)
    return gc.MESH_STIFFNESS * r_base**2, gc.MESH_DAMPING * r_base**2


def add_mesh(mbs, node_a: int, node_b: int, stiffness: float, damping: float) -> None:
    """An external mesh between two nodes' first Tait-Bryan angles (about global x): the
    torque -k (theta_a + theta_b) - c (omega_a + omega_b) on both."""
    n = 2 * RXYZ_SIZE  # the two nodes' coordinates, one after the other
    angles = (ANGLE_X, RXYZ_SIZE + ANGLE_X)
    matrices = []
    for value in (0.0, stiffness, damping):  # mass (none), stiffness, damping
        m = exu.MatrixContainer()
        m.SetWithSparseMatrix([[i, j, value] for i in angles for j in angles] if value else [],
                              n, n)
        matrices.append(m)
    mbs.AddObject(ei.ObjectGenericODE2(nodeNumbers=[node_a, node_b], massMatrix=matrices[0],
                                       stiffnessMatrix=matrices[1], dampingMatrix=matrices[2]))


def build_chain(mbs, race: str, n: int) -> int:
    """The shaft chain (``race`` "shaft") or the gear row ("gear") of ``n`` bodies in
    ``mbs``, hinge axes along global x; returns the sensor of the last body's angular
    velocity."""
    ground = mbs.AddObject(ei.ObjectGround())
    m = sc if race == "shaft" else gc
    k_mesh, c_mesh = mesh_stiffness()
    markers, nodes = [], []
    for i in range(n):
        # the gear row is drivedyn's turned by the rotation z -> x, x -> y (no gravity)
        pos = (m.SPACING * i, 0.0, 0.0) if race == "shaft" else (0.0, m.SPACING * i, 0.0)
        node, body = rigid_disk(mbs, pos, m.MASS, m.INERTIA)
        markers.append(hinge(mbs, ground, body, pos))
        nodes.append(node)
        if i > 0 and race == "gear":
            add_mesh(mbs, nodes[i - 1], nodes[i], k_mesh, c_mesh)
        elif i > 0:  # about marker i-1's z axis (global x)
            mbs.AddObject(ei.ObjectConnectorTorsionalSpringDamper(
                markerNumbers=[markers[i - 1], markers[i]], stiffness=sc.STIFFNESS,
                damping=sc.DAMPING))
    mbs.AddLoad(ei.LoadTorqueVector(markerNumber=markers[0], loadVector=[m.TORQUE, 0.0, 0.0]))
    # the damper from the last body to the ground: no stiffness, about the hinge axis
    mg = mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=ground, localHT=exu.HT(
        rotation=Z_ONTO_X, translation=list(pos))))
    mbs.AddObject(ei.ObjectConnectorTorsionalSpringDamper(
        markerNumbers=[mg, markers[-1]], stiffness=0.0,
        damping=sc.DAMPING if race == "shaft" else gc.DAMPER))
    return mbs.AddSensor(ei.SensorNode(
        nodeNumber=nodes[-1], storeInternal=True, writeToFile=False,
        outputVariableType=exu.OutputVariableType.AngularVelocity))


def beam_section():
    """Exudyn's section data from drivedyn's section properties (same numbers)."""
    p = fs.SECTION.properties(dd.STEEL)
    sec = exu.BeamSection()
    sec.stiffnessMatrix = np.diag(p.stiffness)  # EA, GA_y, GA_z, GJ, EI_y, EI_z
    sec.inertia = np.diag(p.rotary_inertia)  # rho J_p, rho I_y, rho I_z [kg m]
    sec.massPerLength = p.mass_per_length
    return sec


def beam_damping(le: float) -> np.ndarray:
    """The material damping of one element of length ``le`` as a damper between its nodes:
    (6, 6) in node A's frame, beta GJ / L and beta EI / L on the relative angular velocity
    (the twist and curvature rates times L, to first order), none on the translations."""
    k = fs.SECTION.properties(dd.STEEL).stiffness
    return np.diag(np.concatenate([np.zeros(3), fs.DAMPING * k[3:] / le]))


def build_beam(mbs, n: int, lumped: bool = True) -> int:
    """The spinning shaft of ``n`` elements (``n`` even) in ``mbs``; ``lumped``: the
    elements' lumped mass matrix (drivedyn's default) instead of Exudyn's consistent one.
    Returns the sensor of the mid-span node's position."""
    # a process-wide switch of Exudyn's, read when the solver computes the mass matrix
    exu.special.beams.geometricallyExactLumpedMass = lumped
    ground = mbs.AddObject(ei.ObjectGround())
    w = fs.SPEED
    le = fs.LENGTH / n
    nodes = [mbs.AddNode(ei.NodeRigidBodyRxyz(referenceCoordinates=[le * i, 0, 0, 0, 0, 0],
                                              initialVelocities=[0, 0, 0, w, 0, 0]))
             for i in range(n + 1)]
    sec = beam_section()
    damping = beam_damping(le)
    for i in range(n):
        e = mbs.AddObject(ei.ObjectBeamGeometricallyExact(nodeNumbers=[nodes[i], nodes[i + 1]],
                                                          length=le, sectionData=sec))
        mbs.AddLoad(ei.LoadMassProportional(
            markerNumber=mbs.AddMarker(ei.MarkerBodyMass(bodyNumber=e)), loadVector=GRAVITY))
        mbs.AddObject(ei.ObjectConnectorRigidBodySpringDamper(damping=damping, markerNumbers=[
            mbs.AddMarker(ei.MarkerNodeRigid(nodeNumber=nodes[i])),
            mbs.AddMarker(ei.MarkerNodeRigid(nodeNumber=nodes[i + 1]))]))
    mid = nodes[n // 2]
    # the unbalance: 50 mm off the axis along z, turning with the shaft
    r = np.array([0.0, 0.0, fs.UNBALANCE_RADIUS])
    nu = mbs.AddNode(ei.NodeRigidBodyRxyz(
        referenceCoordinates=[fs.LENGTH / 2, 0.0, r[2], 0.0, 0.0, 0.0],
        initialVelocities=[*np.cross([w, 0.0, 0.0], r), w, 0.0, 0.0]))
    bu = mbs.AddObject(ei.ObjectRigidBody(mass=fs.UNBALANCE_MASS, nodeNumber=nu,
                                          inertia=[UNBALANCE_INERTIA] * 3 + [0.0] * 3))
    mbs.AddLoad(ei.LoadMassProportional(markerNumber=mbs.AddMarker(ei.MarkerBodyMass(
        bodyNumber=bu)), loadVector=GRAVITY))
    mbs.AddObject(ei.ObjectJointGeneric(markerNumbers=[
        mbs.AddMarker(ei.MarkerNodeRigid(nodeNumber=mid)),
        mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=bu, localPosition=list(-r)))]))
    # bearings: a revolute joint about x at x = 0, a cylindrical joint (free along and
    # about x) at x = L
    ht = exu.HT(rotation=Z_ONTO_X, translation=[0.0, 0.0, 0.0])
    left = mbs.AddMarker(ei.MarkerNodeRigid(nodeNumber=nodes[0], localHT=ht))
    mbs.AddObject(ei.ObjectJointRevoluteZ(markerNumbers=[mbs.AddMarker(ei.MarkerBodyRigid(
        bodyNumber=ground, localHT=ht)), left]))
    mbs.AddObject(ei.ObjectJointGeneric(constrainedAxes=[0, 1, 1, 0, 1, 1], markerNumbers=[
        mbs.AddMarker(ei.MarkerBodyRigid(bodyNumber=ground, localPosition=[fs.LENGTH, 0, 0])),
        mbs.AddMarker(ei.MarkerNodeRigid(nodeNumber=nodes[-1]))]))
    # the speed driver: node 0's spin rate (its Tait-Bryan angle about x) held at w
    mbs.AddObject(ei.ObjectConnectorCoordinate(velocityLevel=True, offset=w, markerNumbers=[
        mbs.AddMarker(ei.MarkerNodeCoordinate(
            nodeNumber=mbs.AddNode(ei.NodePointGround()), coordinate=0)),
        mbs.AddMarker(ei.MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=ANGLE_X))]))
    return mbs.AddSensor(ei.SensorNode(nodeNumber=mid, storeInternal=True, writeToFile=False,
                                       outputVariableType=exu.OutputVariableType.Position))


def exudyn_run(race: str, n: int, t_end: float, linear_solver: str = "sparse",
               beam_mass: str = "lumped", rtol: float = NEWTON_RTOL) -> dict:
    """Build and run one race in Exudyn; the timings, Exudyn's counts and the figure."""
    t0 = time.perf_counter()
    SC = exu.SystemContainer()  # owns mbs: kept until the results are read
    mbs = SC.AddSystem()
    if race == "beam":
        sensor = build_beam(mbs, n, beam_mass == "lumped")
    else:
        sensor = build_chain(mbs, race, n)
    mbs.Assemble()
    build_s = time.perf_counter() - t0
    step = {"shaft": sc.FIXED, "gear": gc.FIXED, "beam": fs.STEP}[race].h
    rho = {"shaft": sc.INTEGRATOR, "gear": gc.INTEGRATOR, "beam": fs.INTEGRATOR}[race].rho_inf
    out_dt = {"shaft": sc.OUTPUT_DT, "gear": gc.OUTPUT_DT, "beam": BEAM_OUTPUT_DT}[race]
    s = settings(t_end, step, rho, out_dt, linear_solver, rtol)
    t0 = time.perf_counter()
    ok = mbs.SolveDynamic(s)
    wall = time.perf_counter() - t0
    it = mbs.sys["dynamicSolver"].it
    out = {"race": race, "N": n, "exudyn_wall_s": round(wall, 4),
           "exudyn_build_s": round(build_s, 4), "steps": int(it.currentStepIndex) - 1,
           "newton_iterations": int(it.newtonStepsCount),
           "jacobians": int(it.newtonJacobiCount), "success": bool(ok)}
    data = mbs.GetSensorStoredData(sensor)  # rows: t, then the 3 components
    if race == "beam":
        half = data[data[:, 0] >= 0.5 * t_end - 1e-12]
        out["whirl_mm"] = round(1e3 * float(np.hypot(half[:, 2], half[:, 3]).mean()), 4)
    else:  # about x
        out["omega_last"] = float(data[-1, 1])
    return out


def drivedyn_run(race: str, n: int, t_end: float) -> dict:
    """The drivedyn script's own timed run of the same race, after its warm-up."""
    if race == "shaft":
        sc.run(n, dd.FixedStep(1e-4), 5e-4)
        return sc.run(n, sc.FIXED, t_end)
    if race == "gear":
        gc.run(n, dd.FixedStep(1e-4), 5e-4)
        return gc.run(n, gc.FIXED, t_end)
    fs.run(n, 2e-3)
    return fs.run(n, t_end, BEAM_OUTPUT_DT)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", default=",".join(RACES),
                    help="comma-separated races: shaft, gear, beam (default: all)")
    ap.add_argument("--n", type=int, nargs="+", default=[200],
                    help="chain lengths of shaft and gear (default: 200)")
    ap.add_argument("--t-end", type=float, default=1.0, help="simulated time [s]")
    ap.add_argument("--beam-elements", type=int, nargs="+", default=[100],
                    help="elements of the beam (even; default: 100)")
    ap.add_argument("--drivedyn", action="store_true",
                    help="also run drivedyn's timed run and print the ratio")
    ap.add_argument("--linear-solver", choices=("sparse", "dense"), default="sparse",
                    help="Exudyn's LU: EigenSparse (default) or EXUdense")
    ap.add_argument("--beam-mass", choices=("lumped", "consistent"), default="lumped",
                    help="Exudyn's beam mass matrix: lumped (drivedyn's default) or consistent "
                         "(Exudyn's default)")
    ap.add_argument("--exudyn-rtol", type=float, default=NEWTON_RTOL,
                    help="Exudyn's Newton relativeTolerance (default 1e-6; Exudyn's own "
                         "default 1e-8 stalls in the 100-element beam)")
    ap.add_argument("--exudyn-fast", action="store_true",
                    help="Exudyn's module without range checks (exudynCPPfast)")
    args = ap.parse_args()
    races = [r.strip() for r in args.runs.split(",") if r.strip()]
    bad = [r for r in races if r not in RACES]
    if bad:
        ap.error(f"--runs: unknown race(s) {', '.join(bad)}; choose from {', '.join(RACES)}")
    if any(m % 2 for m in args.beam_elements):
        ap.error("--beam-elements: the unbalance sits on the mid-span node, give even numbers")
    module = load_exudyn(args.exudyn_fast)

    for race in races:
        for n in args.beam_elements if race == "beam" else args.n:
            options = (args.linear_solver, args.beam_mass, args.exudyn_rtol)
            exudyn_run(race, n, WARMUP_T, *options)  # a few steps first
            out = exudyn_run(race, n, args.t_end, *options)
            out["exudyn_module"] = module
            out["exudyn_rtol"] = args.exudyn_rtol
            if args.drivedyn:
                d = drivedyn_run(race, n, args.t_end)
                key = "whirl_mm" if race == "beam" else "omega_last"
                out["drivedyn_wall_s"] = d["wall_s"]
                out["ratio"] = round(d["wall_s"] / out["exudyn_wall_s"], 4)
                out[f"drivedyn_{key}"] = d[key]
                out["figure_rel_diff"] = float(f"{out[key] / d[key] - 1.0:.3e}")
                out["drivedyn_steps"] = d["steps"]
            print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
