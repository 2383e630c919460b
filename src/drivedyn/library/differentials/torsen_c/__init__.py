"""TORSEN Type C (epicyclic, central) differential, after seed 003: the parametric model
(:mod:`.model`), its model-file schema (:mod:`.schema`, default file ``torsen-c``) and the
independent quasi-static TDR (:mod:`.analytic`)."""

from __future__ import annotations

from drivedyn.library.differentials.base import Differential, Mode, Output, matcher
from drivedyn.library.differentials.torsen_c import analytic, model
from drivedyn.library.differentials.torsen_c.schema import TorsenCFile


def _fixed_speeds(p: TorsenCFile, dw: float) -> tuple[float, float]:
    # housing held: z_s w_s = -z_r w_r and |w_r - w_s| = dw
    rho = p.gears.teeth_ring / p.gears.teeth_sun
    return rho * dw / (1 + rho), dw / (1 + rho)


def _housing_speed(p: TorsenCFile, w_front: float, w_rear: float) -> float:
    g = p.gears
    return (g.teeth_sun * w_front + g.teeth_ring * w_rear) / (g.teeth_sun + g.teeth_ring)


#: element names of the planet pockets and of the gear meshes (glob patterns)
POCKETS = ("*_pocket",)
MESHES = ("sun_planet*", "planet*_ring")

DIFFERENTIAL = Differential(
    name="torsen-c",
    library="torsen_c",
    title="TORSEN Type C (central, epicyclic)",
    schema=TorsenCFile,
    outputs=(Output("front", "sun", "sun_bearing", "b_sun", "front output (sun)"),
             Output("rear", "coupling", "coupling_bearing", "b_coupling",
                    "rear output (coupling)")),
    modes=tuple(Mode(*m) for m in model.MODES),
    check=model.check_parameters,
    build=lambda p, omega, fs: model.build_spec(p, omega, fs),
    housing_fixed_speeds=_fixed_speeds,
    housing_speed=_housing_speed,
    analytic_bench=analytic.bench_tdr,
    analytic_vehicle=analytic.vehicle_torques,
    # one boundary-friction coefficient for the steel contacts in the oil (W1, W3-W5 and the
    # pockets; W2: the paper's 0.03): one number for four modes. Two numbers (washers,
    # pockets) end on the upper bound 0.2 of their range (docs/torsen_c.md)
    free=(("washers.sun_housing.mu", "washers.coupling_case.mu", "washers.ring_housing.mu",
           "washers.ring_case.mu", "pockets.mu"),),
    seed_coordinates=8161,
    washers={"sun_housing": "W1 sun - housing", "sun_coupling": "W2 sun - coupling",
             "coupling_case": "W3 coupling - case", "ring_housing": "W4 ring - housing",
             "ring_case": "W5 ring - case"},
    axial_bodies=(("sun", "sun"), ("ring", "internal gear (ring)"), ("coupling", "coupling")),
    mesh_elements=matcher(MESHES),
    pocket_elements=matcher(POCKETS),
    element_groups=(("pockets", POCKETS), ("gear meshes", MESHES)),
)
