"""``linear_modes``: linearised eigenfrequencies of small mechanisms with exact answers.

Joints are eliminated by a null-space basis, massless coordinates condensed statically, and
the damped problem solved in first-order form; each is checked on a system whose frequencies
are known in closed form.
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd

Z = (0.0, 0.0, 1.0)


def _slider(spec: dd.Spec, name: str, x: float, mass: float) -> None:
    """A block of ``mass`` at (x, 0, 0) on a prismatic joint along global x."""
    spec.add_rigid_body(name, mass, (1e-3, 1e-3, 1e-3), position=(x, 0.0, 0.0))
    spec.add_marker(f"{name}_guide", dd.GROUND, position=(x, 0.0, 0.0), axis=(1, 0, 0))
    spec.add_marker(f"{name}_c", name, axis=(1, 0, 0))
    spec.add(dd.Prismatic(f"{name}_slide", f"{name}_guide", f"{name}_c"))


def test_mass_on_a_spring():
    k, m = 4.0e3, 2.5
    spec = dd.Spec()
    _slider(spec, "block", 1.0, m)
    spec.add_marker("anchor", dd.GROUND)
    spec.add_marker("hook", "block")
    spec.add(dd.SpringDamper("spring", "anchor", "hook", stiffness=k))
    modes = dd.linear_modes(dd.compile_model(spec), n_modes=1)
    assert modes.frequencies[0] == pytest.approx(np.sqrt(k / m) / (2 * np.pi), rel=1e-10)
    assert "block" in modes.labels[0] and "ux" in modes.labels[0]
    assert f"{modes.frequencies[0]:.5g}" in modes.table()


def test_two_masses_three_springs():
    """wall -k- m -k- m -k- wall: omega^2 = k/m and 3 k/m."""
    k, m = 1.0e3, 1.5
    spec = dd.Spec()
    _slider(spec, "a", 1.0, m)
    _slider(spec, "b", 2.0, m)
    spec.add_marker("wall_l", dd.GROUND)
    spec.add_marker("wall_r", dd.GROUND, position=(3.0, 0, 0))
    for n in ("a", "b"):
        spec.add_marker(f"{n}_p", n)
    spec.add(dd.SpringDamper("s1", "wall_l", "a_p", stiffness=k))
    spec.add(dd.SpringDamper("s2", "a_p", "b_p", stiffness=k))
    spec.add(dd.SpringDamper("s3", "b_p", "wall_r", stiffness=k))
    modes = dd.linear_modes(dd.compile_model(spec), n_modes=2)
    np.testing.assert_allclose(modes.omega, np.sqrt([k / m, 3 * k / m]), rtol=1e-10)


def test_massless_node_between_two_springs_is_condensed():
    """wall -k1- node (no mass) -k2- m: one mode with the series stiffness."""
    k1, k2, m = 3.0e3, 6.0e3, 2.0
    spec = dd.Spec()
    _slider(spec, "block", 2.0, m)
    spec.add_node("middle", (1.0, 0.0, 0.0))
    spec.add_marker("mid_guide", dd.GROUND, position=(1.0, 0, 0), axis=(1, 0, 0))
    spec.add_marker("mid_c", "middle", axis=(1, 0, 0))
    spec.add(dd.Prismatic("mid_slide", "mid_guide", "mid_c"))
    spec.add_marker("wall", dd.GROUND)
    spec.add_marker("mid_p", "middle")
    spec.add_marker("block_p", "block")
    spec.add(dd.SpringDamper("s1", "wall", "mid_p", stiffness=k1))
    spec.add(dd.SpringDamper("s2", "mid_p", "block_p", stiffness=k2))
    modes = dd.linear_modes(dd.compile_model(spec), n_modes=3)
    ks = k1 * k2 / (k1 + k2)
    assert modes.omega[0] == pytest.approx(np.sqrt(ks / m), rel=1e-10)


def test_damped_spring_mass():
    k, m, c = 4.0e3, 2.5, 20.0
    spec = dd.Spec()
    _slider(spec, "block", 1.0, m)
    spec.add_marker("anchor", dd.GROUND)
    spec.add_marker("hook", "block")
    spec.add(dd.SpringDamper("spring", "anchor", "hook", stiffness=k, damping=c))
    modes = dd.linear_modes(dd.compile_model(spec), n_modes=1, damped=True)
    zeta = c / (2 * np.sqrt(k * m))
    wn = np.sqrt(k / m)
    assert modes.damping_ratio[0] == pytest.approx(zeta, rel=1e-10)
    assert modes.omega[0] == pytest.approx(wn * np.sqrt(1 - zeta**2), rel=1e-10)


def test_a_model_without_free_coordinates_is_refused():
    spec = dd.Spec()
    spec.add_rigid_body("block", 1.0, (1, 1, 1))
    spec.add_marker("g", dd.GROUND)
    spec.add_marker("b", "block")
    spec.add(dd.Fixed("weld", "g", "b"))
    with pytest.raises(ValueError, match="no free coordinate"):
        dd.linear_modes(dd.compile_model(spec))
