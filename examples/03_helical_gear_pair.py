"""Example 03: a helical gear pair driven by a motor against a load.

A 19-tooth pinion (right hand, 18 deg helix) drives a 47-tooth wheel (left hand); both turn
on hinges to the ground about global z. The pinion's speed is ramped up to 150 rad/s by a
speed driver; the wheel carries a constant load torque of 120 N m. The mesh stiffness comes
from ISO 6336-1 method B (steel, solid wheels), the damping from a damping ratio of 0.07,
the backlash is 80 um and the teeth have a friction coefficient of 0.05.

The script prints the ISO 6336 figures, then the steady mesh forces next to the DIN 3990 /
ISO 6336 relations of a helical mesh

    F_a = F_t tan(beta),   F_r = F_t tan(alpha_n) / cos(beta),   F_n = F_t / (cos alpha_n cos beta)

(tooth friction acts as a couple on the wheels, so these relations hold for the mesh force
with friction too), the mesh deflection F_n / k_m, the speed ratio and the efficiency next
to the ISO/TR 14179-2 estimate 1 - mu H_V.

Run it with ``python examples/03_helical_gear_pair.py`` (a few seconds once the numba kernels
are compiled; the first run compiles them, about two minutes).
"""

from __future__ import annotations

import numpy as np

import drivedyn as dd
from drivedyn.elements.gears import CylindricalPair, mesh_info

# -- gear data (SI units) --------------------------------------------------------------------
Z_PINION, Z_WHEEL = 19, 47
MODULE = 2.5e-3  # normal module [m]
PRESSURE_ANGLE = np.radians(20.0)  # normal pressure angle [rad]
HELIX = np.radians(18.0)  # pinion helix angle, right hand [rad]; the wheel is left hand
FACE_WIDTH = 0.025  # [m]
BACKLASH = 80e-6  # transverse backlash along the line of action [m]
MU = 0.05  # tooth friction coefficient
SPEED = 150.0  # pinion speed [rad/s]
LOAD = 120.0  # load torque on the wheel [N m]


def build_model() -> dd.Model:
    """The pinion at the origin, the wheel at the working centre distance along x."""
    geo = CylindricalPair.build(Z_PINION, Z_WHEEL, MODULE, PRESSURE_ANGLE, HELIX)
    a = geo.centre_distance
    z = (0.0, 0.0, 1.0)
    spec = dd.Spec()
    spec.add_rigid_body("pinion", 0.8, (4e-4, 4e-4, 3e-4))
    spec.add_rigid_body("wheel", 4.0, (8e-3, 8e-3, 1.2e-2), position=(a, 0.0, 0.0))
    # each wheel's marker at its centre, z = wheel axis; hinges to the ground
    spec.add_marker("bearing_p", dd.GROUND, axis=z)
    spec.add_marker("pinion_axis", "pinion", axis=z)
    spec.add_marker("bearing_w", dd.GROUND, position=(a, 0.0, 0.0), axis=z)
    spec.add_marker("wheel_axis", "wheel", axis=z)
    spec.add(dd.Hinge("pinion_bearing", "bearing_p", "pinion_axis"))
    spec.add(dd.Hinge("wheel_bearing", "bearing_w", "wheel_axis"))
    spec.add(dd.GearPair(
        "mesh", "pinion_axis", "wheel_axis", Z_PINION, Z_WHEEL, MODULE, FACE_WIDTH,
        pressure_angle=PRESSURE_ANGLE, helix_angle=HELIX, helix_angle_b=-HELIX,
        damping_ratio=0.07, backlash=BACKLASH, friction=MU, friction_velocity=1e-3,
    ))
    spec.add(dd.JointDriver("motor", "pinion_bearing", dd.SmoothStep(0.0, 0.1, 0.0, SPEED),
                            quantity="speed"))
    # the wheel turns negatively about z: a positive torque resists it
    spec.add(dd.Torque("load", "wheel_axis", vector=(0.0, 0.0, LOAD)))
    return dd.compile_model(spec)


def main() -> dict[str, float]:
    """Simulate 0.3 s; print and return the figures."""
    model = build_model()
    geo = CylindricalPair.build(Z_PINION, Z_WHEEL, MODULE, PRESSURE_ANGLE, HELIX)
    info = mesh_info(model, "mesh")
    res = dd.simulate(model, 0.3, integrator=dd.GeneralizedAlpha(0.9), step=dd.FixedStep(5e-5),
                      output_dt=1e-3)
    if not res.success:
        raise RuntimeError(res.message)

    def last(name: str) -> float:
        return float(res[f"mesh.{name}"].values[-1])

    Ft, Fr, Fa, Fn = (last(k) for k in ("tangential_force", "radial_force", "axial_force",
                                        "normal_force"))
    ca, cb = np.cos(PRESSURE_ANGLE), np.cos(HELIX)
    err_a = abs(abs(Fa) / (Ft * np.tan(HELIX)) - 1.0)
    err_r = abs(Fr / (Ft * np.tan(PRESSURE_ANGLE) / cb) - 1.0)
    err_n = abs(Fn / (Ft / (ca * cb)) - 1.0)
    err_d = abs(last("deflection") / (Fn / info["stiffness"]) - 1.0)
    w_p = res["pinion.angular_velocity"].values[-1, 2]
    w_w = res["wheel.angular_velocity"].values[-1, 2]
    p_in = float(res["motor.power"].values[-1])
    p_out = -LOAD * w_w
    u = Z_WHEEL / Z_PINION
    h_v = (np.pi * (u + 1) / (Z_PINION * u * np.cos(geo.beta_b))
           * (1 - geo.eps_alpha + geo.eps_1**2 + geo.eps_2**2))
    c_gamma = info["stiffness"] / (FACE_WIDTH * 1e9)  # N/(mm um)

    print(f"transverse contact ratio        {geo.eps_alpha:.4f}")
    print(f"ISO 6336 mesh stiffness         c_gamma_alpha = {c_gamma:.3f} N/(mm um), "
          f"k_m = {info['stiffness']:.4g} N/m")
    print(f"mesh damping                    {info['damping']:.4g} N s/m (zeta = 0.07)")
    print(f"tangential force on the wheel   {Ft:10.3f} N")
    print(f"axial force / (F_t tan beta)    {abs(Fa) / (Ft * np.tan(HELIX)):.12f}")
    print(f"radial / (F_t tan a_n / cos b)  {Fr / (Ft * np.tan(PRESSURE_ANGLE) / cb):.12f}")
    print(f"normal / (F_t / cos a_n cos b)  {Fn / (Ft / (ca * cb)):.12f}")
    print(f"deflection / (F_n / k_m)        {last('deflection') / (Fn / info['stiffness']):.12f}")
    print(f"speed ratio wheel / pinion      {w_w / w_p:.9f}  (-z1/z2 = {-Z_PINION / Z_WHEEL:.9f})")
    print(f"sliding speed, friction power   {last('sliding_velocity'):.4f} m/s, "
          f"{last('friction_power'):.3f} W")
    print(f"efficiency                      {p_out / p_in:.5f}  (1 - mu H_V = "
          f"{1 - MU * h_v:.5f})")
    print(f"energy balance error            "
          f"{np.abs(res['energy.balance_error'].values).max():.3g} J of "
          f"{res['energy.work_in'].values[-1]:.4g} J supplied")
    print(f"run                             {res}")
    return {
        "force_axial_error": float(err_a),
        "force_radial_error": float(err_r),
        "force_normal_error": float(err_n),
        "deflection_error": float(err_d),
        "ratio_error": float(abs((w_w / w_p) / (-Z_PINION / Z_WHEEL) - 1)),
        "efficiency": float(p_out / p_in),
        "efficiency_iso": float(1 - MU * h_v),
        "c_gamma_alpha": float(c_gamma),
    }


if __name__ == "__main__":
    main()
