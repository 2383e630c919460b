"""TORSEN Type B in its vehicle configuration: wall time per simulated second of each
held level, loaded holds against zero-torque holds (``_differential_vehicle.py``).

    python benchmarks/torsen_b_vehicle.py              # shipped profile (4 levels, then backwards)
    python benchmarks/torsen_b_vehicle.py --short      # holds 0.12 s, ramps 0.05 s
    python benchmarks/torsen_b_vehicle.py --set vehicle.hold=0.3
"""

from _differential_vehicle import main

if __name__ == "__main__":
    main("torsen-b", "TORSEN Type B in its vehicle configuration")
