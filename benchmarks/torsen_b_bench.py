"""Benchmark: the TORSEN Type B front/rear differential on the test bench, all four modes.

The shipped ``torsen-b`` model file (``drivedyn.library.differentials.torsen_b``: housing with
ten pockets, two helical side gears on cylindrical joints, five pairs of element gears on
parallel-axes guides with tip friction in the pocket bores and end-face friction, 10 side and
10 end meshes with mesh-stiffness variation and backlash, three thrust washers) on the seed
003 bench protocol of its ``[bench]`` table: housing held, 125 N m on one side gear, the other
side gear's speed prescribed for 20 rpm; drive then coast. Two runs (torque on the right:
modes 1, 2; on the left: modes 3, 4). The aim: below 10 s for the four modes on two cores.

Prints the TDR table (simulated, analytic quasi-static, measured, differences), per run the
wall time, build time, steps, rejected steps, Newton iterations and LU factorizations, the
total wall time and the peak RSS, then one JSON line.

Usage::

    python benchmarks/torsen_b_bench.py
    python benchmarks/torsen_b_bench.py --set gears.stiffness_variation=false
"""

from _differential_bench import main

if __name__ == "__main__":
    main("torsen-b", "TORSEN Type B on the test bench, all four modes")
