"""Example 04: a helical planetary set (sun, three planets on a carrier, ring).

Sun (24 teeth), three planets (18) and the ring (60, internal) mesh through six gear pairs;
sun, ring and carrier turn on hinges to the ground about global z, the planets on hinges on
the carrier. The ring is held by an angle driver (its torque is the ring's reaction); the
sun is driven at 100 rad/s by a speed driver and the carrier carries a load torque of
200 N m. This is the reduction the TORSEN type C differential is built around.

Exact references (no friction):

* Willis: (w_sun - w_carrier) / (w_ring - w_carrier) = -z_ring / z_sun, so with the ring
  held w_carrier = w_sun z_sun / (z_sun + z_ring);
* torque split: T_ring / T_sun = z_ring / z_sun, T_carrier = -(T_sun + T_ring);
* the planets share the load equally.

The gear element measures each wheel's rotation against the centre line of its mesh, which
turns with the carrier, so the Willis equation comes out of the model without any special
treatment of planets.

Run it with ``python examples/04_planetary_set.py`` (a few seconds once compiled).
"""

from __future__ import annotations

import numpy as np

import drivedyn as dd

Z_SUN, Z_PLANET, Z_RING = 24, 18, 60
MODULE = 2e-3  # normal module [m]
HELIX = np.radians(15.0)  # sun right hand; planets and ring left hand
FACE_WIDTH = 0.015  # [m]
N_PLANETS = 3
SUN_SPEED = 100.0  # [rad/s]
LOAD = 200.0  # load torque on the carrier [N m]


def build_model() -> dd.Model:
    r_sun = Z_SUN * MODULE / (2 * np.cos(HELIX))
    r_planet = Z_PLANET * MODULE / (2 * np.cos(HELIX))
    z = (0.0, 0.0, 1.0)
    spec = dd.Spec()
    spec.add_rigid_body("sun", 1.0, (1e-3, 1e-3, 1.5e-3))
    spec.add_rigid_body("ring", 3.0, (2e-2, 2e-2, 3e-2))
    spec.add_rigid_body("carrier", 2.0, (5e-3, 5e-3, 8e-3))
    for name in ("sun", "ring", "carrier"):
        spec.add_marker(f"{name}_bearing", dd.GROUND, axis=z)
        spec.add_marker(f"{name}_axis", name, axis=z)
        spec.add(dd.Hinge(f"{name}_hinge", f"{name}_bearing", f"{name}_axis"))
    for k in range(N_PLANETS):
        angle = 2 * np.pi * k / N_PLANETS
        pos = (r_sun + r_planet) * np.array([np.cos(angle), np.sin(angle), 0.0])
        spec.add_rigid_body(f"planet{k}", 0.3, (1e-4, 1e-4, 1.5e-4), position=pos)
        spec.add_marker(f"pin{k}", "carrier", position=pos, axis=z)
        spec.add_marker(f"planet{k}_axis", f"planet{k}", axis=z)
        spec.add(dd.Hinge(f"planet{k}_hinge", f"pin{k}", f"planet{k}_axis"))
        spec.add(dd.GearPair(f"sun_planet{k}", "sun_axis", f"planet{k}_axis", Z_SUN, Z_PLANET,
                             MODULE, FACE_WIDTH, helix_angle=HELIX, damping_ratio=0.05))
        # ring = wheel B, internal; the planet (A) and the ring have the same hand
        spec.add(dd.GearPair(f"planet{k}_ring", f"planet{k}_axis", "ring_axis", Z_PLANET,
                             Z_RING, MODULE, FACE_WIDTH, helix_angle=-HELIX, internal="b",
                             damping_ratio=0.05))
    spec.add(dd.JointDriver("motor", "sun_hinge", dd.SmoothStep(0.0, 0.05, 0.0, SUN_SPEED),
                            quantity="speed"))
    spec.add(dd.JointDriver("ring_holder", "ring_hinge", 0.0, quantity="angle"))
    spec.add(dd.Torque("load", "carrier_axis", vector=(0.0, 0.0, -LOAD)))
    return dd.compile_model(spec)


def main() -> dict[str, float]:
    """Simulate 0.3 s; print and return the figures."""
    model = build_model()
    res = dd.simulate(model, 0.3, integrator=dd.GeneralizedAlpha(0.9), step=dd.FixedStep(1e-4),
                      output_dt=1e-3)
    if not res.success:
        raise RuntimeError(res.message)
    w_c = float(res["carrier.angular_velocity"].values[-1, 2])
    w_c_ref = SUN_SPEED * Z_SUN / (Z_SUN + Z_RING)
    t_sun = -sum(float(res[f"sun_planet{k}.torque_a"].values[-1]) for k in range(N_PLANETS))
    t_ring = float(res["ring_holder.torque"].values[-1])
    loads = [float(res[f"sun_planet{k}.normal_force"].values[-1]) for k in range(N_PLANETS)]
    revs = float(res["sun_planet0.angle_b"].values[-1]) / (2 * np.pi)
    print(f"carrier speed           {w_c:.9f} rad/s  (Willis: {w_c_ref:.9f})")
    print(f"sun torque (from motor) {t_sun:10.4f} N m")
    print(f"ring reaction torque    {t_ring:10.4f} N m  (z_ring/z_sun x sun torque = "
          f"{Z_RING / Z_SUN * t_sun:.4f})")
    print(f"carrier load            {LOAD:10.4f} N m  (sun + ring = {t_sun + t_ring:.4f})")
    print(f"sun-planet normal forces {', '.join(f'{f:.4f}' for f in loads)} N")
    print(f"planet 0 revolutions relative to the carrier: {revs:.3f}")
    print(f"run                     {res}")
    return {
        "willis_error": abs(w_c / w_c_ref - 1.0),
        "torque_split": t_ring / t_sun,
        "torque_split_error": abs(t_ring / t_sun / (Z_RING / Z_SUN) - 1.0),
        "load_sharing_spread": float(np.ptp(loads) / np.mean(loads)),
    }


if __name__ == "__main__":
    main()
