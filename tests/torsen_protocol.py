"""The short Type C bench protocol shared by the TORSEN test modules (imported by name:
``tests`` is on ``pythonpath``).

``TYPE_C_SHORT``: a 1.1 s bench (ramp 0.1 s, drive window 0.25-0.45 s, transition
0.5-0.8 s, coast window 0.9-1.1 s) with a constant mesh stiffness: the tests that use it
check quasi-static identities to solver precision, which the mesh-stiffness ripple of the
shipped file would blur (its effect is checked in
``test_torsen_c.test_stiffness_variation_keeps_the_tdr``)."""

TYPE_C_SHORT = {
    "gears.stiffness_variation": False,
    "bench.ramp": 0.1,
    "bench.transition": [0.5, 0.8],
    "bench.t_end": 1.1,
    "bench.window_drive": [0.25, 0.45],
    "bench.window_coast": [0.9, 1.1],
}
