"""Example 12: the TORSEN Type B as an FMU, coupled by FMPy to a small vehicle in Python.

``drivedyn fmu torsen-b`` builds an FMI 2.0 co-simulation FMU of the differential (the same
as :func:`drivedyn.fmu.build_fmu` below). A master written here in plain Python couples it to a
rear axle: a car of 1.4 t on two driven wheels (inertia, radius, a simple tyre force law),
the left wheel on ice (mu 0.15), the right on asphalt (mu 0.9). At each 1 ms communication
step the master gives the FMU the housing torque (engine torque through the final drive) and
the two wheel speeds, the FMU returns the torques it delivers to the two half-shafts, and the
master integrates the wheels and the car over the step with them.

An open differential would give both wheels the torque the ice can take; the TORSEN gives
the wheel on asphalt about TDR times more (seed 003: 1.6 in drive), which the script prints
with the car's speed. It runs as a user would run any FMU from FMPy; drivedyn (with
pythonfmu and fmpy: ``pip install "drivedyn[fmu]"``) must be installed in this Python.

Run it with::

    python examples/12_fmu_vehicle.py [--t-end 0.6]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

MASS = 1400.0  # car [kg]
LOAD = 0.5 * MASS * 9.81 / 2  # normal load of each rear wheel [N] (half the car on the axle)
RADIUS = 0.31  # wheel radius [m]
J_WHEEL = 1.2  # wheel with its half-shaft [kg m^2]
MU = {"left": 0.15, "right": 0.9}  # road friction under each wheel
FINAL_DRIVE = 3.9  # engine torque -> housing torque
V0 = 8.0  # starting speed [m/s]


def tyre_force(mu: float, wheel_speed: float, v: float) -> float:
    """Longitudinal tyre force [N]: a Magic-Formula-like curve of the slip ratio."""
    slip = (wheel_speed * RADIUS - v) / max(abs(v), 1.0)
    return mu * LOAD * math.sin(1.6 * math.atan(10.0 * slip))


def engine_torque(t: float) -> float:
    """Engine torque [N m]: 0 to 180 N m over 0.1 s, then held."""
    return 180.0 * min(t / 0.1, 1.0)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t-end", type=float, default=0.6, help="simulated time [s]")
    ap.add_argument("--out", type=Path, default=Path("torsen_b.fmu"), help="the FMU to build")
    args = ap.parse_args(argv)
    try:
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        from drivedyn.fmu import build_fmu
    except ImportError as exc:
        sys.exit(f"this example needs fmpy and pythonfmu ({exc}): pip install 'drivedyn[fmu]'")

    fmu_path = build_fmu("torsen-b", args.out)
    md = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu_path)),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="axle")
    w = {"left": V0 / RADIUS, "right": V0 / RADIUS}  # wheel speeds [rad/s]
    v = V0  # car speed [m/s]
    dt = 1e-3
    n = round(args.t_end / dt)
    wall = time.perf_counter()
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([vr["left_speed"], vr["right_speed"]], [w["left"], w["right"]])
    fmu.exitInitializationMode()
    for i in range(n):
        t = i * dt
        fmu.setReal([vr["input_torque"], vr["left_speed"], vr["right_speed"]],
                     [FINAL_DRIVE * engine_torque(t), w["left"], w["right"]])
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
        shaft = dict(zip(("left", "right"), fmu.getReal([vr["left_torque"],
                                                         vr["right_torque"]]), strict=True))
        force = {s: tyre_force(MU[s], w[s], v) for s in w}
        for s in w:  # the wheels and the car over the step, with the FMU's shaft torques
            w[s] += dt * (shaft[s] - RADIUS * force[s]) / J_WHEEL
        v += dt * (force["left"] + force["right"]) / MASS
    left, right, tdr, housing = fmu.getReal([vr["left_torque"], vr["right_torque"], vr["tdr"],
                                             vr["input_speed"]])
    fmu.terminate()
    fmu.freeInstance()
    wall = time.perf_counter() - wall
    print(f"TORSEN Type B FMU ({fmu_path}) on a rear axle, left wheel on ice (mu "
          f"{MU['left']}), right on asphalt (mu {MU['right']}); {n} steps of {dt * 1e3:g} ms "
          f"in {wall:.1f} s")
    print(f"at t = {args.t_end:g} s: car {v:.2f} m/s (from {V0:g}), wheels left "
          f"{w['left'] * RADIUS:.2f} m/s, right {w['right'] * RADIUS:.2f} m/s, housing "
          f"{housing:.1f} rad/s")
    print(f"half-shaft torques: left {left:.1f} N m, right {right:.1f} N m, TDR {tdr:.3f} "
          f"(an open differential: 1)")
    return {"tdr": tdr, "left": left, "right": right, "v": v, "slip_left": w["left"] * RADIUS
            - v, "wall_s": wall}


if __name__ == "__main__":
    main()
