"""TORSEN Type B (parallel-axis element gears, front/rear axle) differential, after seed 003
and the slides of seed 002: the parametric model (:mod:`.model`), its model-file schema
(:mod:`.schema`, default file ``torsen-b``) and the independent quasi-static TDR
(:mod:`.analytic`)."""

from __future__ import annotations

from drivedyn.library.differentials.base import Differential, Mode, Output, matcher
from drivedyn.library.differentials.torsen_b import analytic, model
from drivedyn.library.differentials.torsen_b.schema import TorsenBFile


def _fixed_speeds(p: TorsenBFile, dw: float) -> tuple[float, float]:
    # housing held: w_l = -w_r, |w_r - w_l| = dw
    return dw / 2, dw / 2


def _housing_speed(p: TorsenBFile, w_left: float, w_right: float) -> float:
    return 0.5 * (w_left + w_right)


#: element names of the pockets, the element gears' end faces and the gear meshes (globs)
POCKETS = ("*_pocket",)
END_FACES = ("*_end_*",)
MESHES = ("left_*", "right_*", "a*_b*")

DIFFERENTIAL = Differential(
    name="torsen-b",
    library="torsen_b",
    title="TORSEN Type B (front/rear, parallel element gears)",
    schema=TorsenBFile,
    outputs=(Output("left", "left", "left_bearing", "b_left", "left output (side gear)"),
             Output("right", "right", "right_bearing", "b_right", "right output (side gear)")),
    modes=tuple(Mode(*m) for m in model.MODES),
    check=model.check_parameters,
    build=lambda p, omega, fs: model.build_spec(p, omega, fs),
    housing_fixed_speeds=_fixed_speeds,
    housing_speed=_housing_speed,
    analytic_bench=analytic.bench_tdr,
    analytic_vehicle=analytic.vehicle_torques,
    # one boundary-friction coefficient for the washers and the pockets (steel on steel in
    # the same oil): one number for two distinct measurements (modes 1 = 3, 2 = 4)
    free=(("washers.mu", "pockets.mu"),),
    seed_coordinates=21164,
    washers={"left": "left side gear - housing", "middle": "between the side gears",
             "right": "right side gear - housing"},
    axial_bodies=(("left", "left side gear"), ("right", "right side gear"),
                  ("a1", "element gear a1"), ("b1", "element gear b1")),
    mesh_elements=matcher(MESHES),
    pocket_elements=matcher(POCKETS),
    element_groups=(("pockets", POCKETS), ("pocket end faces", END_FACES),
                    ("gear meshes", MESHES)),
)
