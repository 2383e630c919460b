"""A rigid gear face pressed on a flexible thrust washer, from the Python API.

A steel washer (r 20..35 mm, 2 mm) is meshed with 27-node hexahedra, reduced by
Craig-Bampton (4 fixed-interface modes and the 8 static modes of its face loads: pressure
and friction) and mounted by its back face on a carrier bolted to the ground. A gear
spinning at 10 rad/s is pushed on it with 2 kN. The example prints the integrated face
pressure against the load, the friction torque against mu F r_m (uniform pressure) and the
washer's largest von Mises stress against the full finite-element model under the same
pressures and their friction tractions.

Run: ``python examples/07_flexible_washer.py``
"""

from __future__ import annotations

import numpy as np

import drivedyn as dd
from drivedyn.fe import (
    Interface,
    SolidMaterial,
    SolidModel,
    annular_washer,
    craig_bampton,
    face_load_patterns,
    von_mises,
)

R_INT, R_EXT, THICK = 0.020, 0.035, 0.002
LOAD, MU, SPIN = 2000.0, 0.1, 10.0


def main() -> dict:
    solid = SolidModel(annular_washer(R_INT, R_EXT, THICK, 2, 36, 1), SolidMaterial())
    back, face = solid.select("z", 0.0), solid.select("z", THICK)
    part = craig_bampton(solid, [Interface("back", back, np.zeros(3))], 4, "washer",
                         loads=face_load_patterns(solid, face))
    sp = dd.Spec()
    sp.add_rigid_body("carrier", 0.5, (1e-3, 1e-3, 2e-3))
    sp.add_rigid_body("gear", 0.3, (3e-4, 3e-4, 5e-4), position=(0, 0, 0.012),
                      angular_velocity=(0, 0, SPIN))
    sp.add_marker("ground_c", "ground", axis=(0, 0, 1))
    sp.add_marker("carrier_mount", "carrier", axis=(0, 0, 1))
    sp.add(dd.Fixed("bolts", "ground_c", "carrier_mount"))
    sp.add_marker("ground_g", "ground", position=(0, 0, 0.012), axis=(0, 0, 1))
    sp.add_marker("gear_axis", "gear", axis=(0, 0, 1))
    sp.add(dd.Cylindrical("bearing", "ground_g", "gear_axis"))
    sp.add(dd.JointDriver("spin", "bearing", SPIN, quantity="speed"))
    sp.add(dd.Force("load", "gear_axis", vector=(0, 0, -LOAD)))
    sp.add_marker("gear_face", "gear", position=(0, 0, -0.010), axis=(0, 0, -1))
    dd.add_flexible_body(sp, "washer", part, "carrier_mount")
    sp.add(dd.FlexibleWasherContact(
        "contact", "carrier_mount", "gear_face", body="washer", face=face,
        law=dd.NormalLaw(1e9, 1.0, law="penalty", damping=2e4),
        friction=dd.FrictionLaw(MU, eps_v=1e-4)))
    res = dd.simulate(dd.compile_model(sp), 0.03, step=dd.FixedStep(1e-4), output_dt=1e-3)
    ds = res.dataset
    F = float(ds["contact.normal_force"].values[-1])
    M = abs(float(ds["contact.friction_torque"].values[-1]))
    rm = 2 * (R_EXT**3 - R_INT**3) / (3 * (R_EXT**2 - R_INT**2))
    # the full FE model under the nodal pressures of the last output and their friction
    # (mu p along the circle, the direction the gear face drags the washer: +e_theta)
    fn = ds["contact.contact_pressure"].values[-1] * solid.face_areas(face)  # nodal forces [N]
    X = solid.nodes[face]
    r = np.hypot(X[:, 0], X[:, 1])
    f = np.zeros(3 * solid.n)
    f[3 * face + 2] = -fn
    f[3 * face] = -MU * fn * X[:, 1] / r
    f[3 * face + 1] = MU * fn * X[:, 0] / r
    u = solid.static((3 * back[:, None] + np.arange(3)).ravel(), f)
    vm_full = float(von_mises(solid.stress_modes(u[:, None])[:, :, 0]).max())
    vm = float(ds["washer.max_von_mises"].values[-1])
    print(f"face force      {F:10.3f} N      (load {LOAD:g} N)")
    print(f"friction torque {M:10.5f} N m    (mu F r_m = {MU * LOAD * rm:.5f} N m)")
    print(f"max von Mises   {vm / 1e6:10.4f} MPa  (full FE model {vm_full / 1e6:.4f} MPa)")
    return {"force": F, "torque": M, "torque_ref": MU * LOAD * rm, "vm": vm, "vm_full": vm_full}


if __name__ == "__main__":
    main()
