"""Example 06: a cantilever rolls up into a circle under an end moment.

A steel rod (1 m, d = 10 mm) modelled by 10 geometrically exact beam elements is clamped at
its root; an end moment about y is ramped to M = 2 pi EI / L, the moment whose curvature
M / EI = 2 pi / L closes the rod into a full circle. The script solves the static equilibrium
at 20 load levels and prints, at each level, the tip position next to the exact circle-arc
solution of Euler's elastica (``x = sin(k L)/k``, ``z = (1 - cos(k L))/k`` with ``k = M/EI``),
then the largest outer-fibre bending stress next to ``M r / I`` (6.6 GPa: an elastic benchmark;
real steel would yield long before). It writes a figure of the
shapes at every fifth level (``beam_rollup.png``). The SE(3) element represents constant
curvature exactly, so the error is Newton's tolerance, not the discretisation.

Run it with ``python examples/06_beam_rollup.py`` (a few seconds once the kernels are
compiled; the first run compiles them, about a minute).
"""

from __future__ import annotations

import numpy as np

import drivedyn as dd

L = 1.0  # rod length [m]
D = 0.01  # diameter [m]
N_ELEMENTS = 10
STEPS = 20


def build() -> tuple[dd.Model, list[str], float]:
    """The clamped rod with its end moment ramped from 0 (t = 0) to 2 pi EI / L (t = 1)."""
    section = dd.SolidCircular(D)
    EI = section.properties(dd.STEEL).stiffness[4]
    spec = dd.Spec()
    nodes = dd.add_straight_beam(spec, "rod", (0, 0, 0), (L, 0, 0), N_ELEMENTS, section,
                                 dd.STEEL)
    spec.add_marker("wall", dd.GROUND)
    spec.add_marker("root", nodes[0])
    spec.add_marker("tip", nodes[-1])
    spec.add(dd.Fixed("clamp", "wall", "root"))
    # a negative moment about y curls the rod towards +z
    spec.add(dd.Torque("end_moment", "tip", (0, -2 * np.pi * EI / L, 0), dd.Ramp(0, 1, 0, 1)))
    return dd.compile_model(spec), nodes, EI


def main() -> dict[str, float]:
    model, nodes, EI = build()
    tip = model.node_index[nodes[-1]]
    st = model.initial_state()
    shapes = []
    worst = 0.0
    print(f"{'M / M_circle':>12}  {'tip x [m]':>10}  {'exact':>10}  {'tip z [m]':>10}  "
          f"{'exact':>10}")
    for k in range(1, STEPS + 1):
        lam = k / STEPS
        st = dd.solve_static(model, st, t=lam)
        kappa = lam * 2 * np.pi / L
        exact = np.array([np.sin(kappa * L) / kappa, 0.0, (1 - np.cos(kappa * L)) / kappa])
        err = float(np.linalg.norm(st.x[tip] - exact))
        worst = max(worst, err)
        print(f"{lam:12.2f}  {st.x[tip, 0]:10.6f}  {exact[0]:10.6f}  {st.x[tip, 2]:10.6f}  "
              f"{exact[2]:10.6f}")
        if k % 5 == 0:
            shapes.append((lam, np.array([st.x[model.node_index[n]] for n in nodes])))
    out = dd.element_outputs(model, st)
    sigma = max(o["normal_stress"] for name, o in out.items() if name.startswith("rod."))
    M = 2 * np.pi * EI / L
    sigma_exact = M * (D / 2) / (np.pi * D**4 / 64)
    print(f"largest tip error {worst:.2e} m; bending stress {sigma / 1e6:.2f} MPa "
          f"(M r / I = {sigma_exact / 1e6:.2f} MPa)")
    _figure(shapes)
    return {"tip_error": worst, "stress_error": abs(sigma - sigma_exact) / sigma_exact}


def _figure(shapes: list[tuple[float, np.ndarray]]) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(111)
    for lam, X in shapes:
        ax.plot(X[:, 0], X[:, 2], "o-", label=f"M = {lam:.2f} x 2 pi EI/L")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.legend(fontsize="small")
    fig.savefig("beam_rollup.png", dpi=110)
    print("figure: beam_rollup.png")


if __name__ == "__main__":
    main()
