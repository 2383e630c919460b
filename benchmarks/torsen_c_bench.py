"""Benchmark: the TORSEN Type C central differential on the test bench, all four modes.

The shipped ``torsen-c`` model file (``drivedyn.library.differentials.torsen_c``: housing
with one pocket per planet, sun, planets on planar guides with pocket contact and tip
friction, internal gear on a helical spline to the coupling, 2 n helical meshes, five thrust
washers) is run on
the seed 003 bench protocol of its ``[bench]`` table: housing held, 125 N m on one output,
the other output's speed prescribed for a 20 rpm speed difference; drive, then a smooth
reversal to coast (default ramp 0.3 s, reversal 1.2-2.0 s, end 3 s, steady windows 0.4-1.0 s
and 2.2-2.8 s). Two runs cover the four locking modes: torque on the rear output (modes 1,
2: drive and coast, bias rear) and on the front output (modes 3, 4, bias front). Solver:
the file's ``[solver]`` table (generalized-alpha, adaptive steps).

Prints a table (mode, simulated TDR, analytic quasi-static TDR of
``drivedyn.library.differentials.torsen_c.analytic``, the measured TDR of the file's
``[experiment]`` table,
the relative differences, window ripple), then per run the wall time of ``simulate``, the
model build time, steps, rejected steps, Newton iterations, LU factorizations, and the total
wall time and peak RSS; finally one JSON line with all of it. The warm-up (a 2 ms run of
the rear bench) compiles the numba kernels on the very first run on a machine (~1-2 min) and
loads them from the cache afterwards.

Usage::

    python benchmarks/torsen_c_bench.py
    python benchmarks/torsen_c_bench.py --set pockets.mu=0.1 --set bench.t_end=3.0
"""

from _differential_bench import main

if __name__ == "__main__":
    main("torsen-c", "TORSEN Type C on the test bench, all four modes")
