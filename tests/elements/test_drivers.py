"""Drivers: prescribed angle, speed and speed difference; the multiplier is the torque."""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd

J1, J2 = 0.02, 0.05  # polar inertias of the two disks [kg m^2]


def disks(n: int = 2) -> dd.Spec:
    spec = dd.Spec()
    for i, J in enumerate((J1, J2)[:n]):
        spec.add_rigid_body(f"d{i}", 1.0, [0.6 * J, 0.6 * J, J], position=(0.0, 0.0, 0.2 * i))
        spec.add_marker(f"g{i}", "ground", position=(0.0, 0.0, 0.2 * i), axis=(0, 0, 1))
        spec.add_marker(f"m{i}", f"d{i}", axis=(0, 0, 1))
        spec.add(dd.Hinge(f"h{i}", f"g{i}", f"m{i}"))
    return spec


def test_speed_driver_torque_balances_a_damper():
    """Constant speed w against a torsional damper c to the ground: the driver supplies the
    torque c w, and its work equals the energy dissipated (steady state) plus the kinetic
    energy it gave the disk."""
    c, w = 0.3, 12.0
    spec = disks(1)
    spec.add(dd.TorsionalSpringDamper("damp", "g0", "m0", damping=c))
    spec.add(dd.JointDriver("drive", "h0", dd.SmoothStep(0.0, 0.1, 0.0, w), quantity="speed"))
    res = dd.simulate(dd.compile_model(spec), 0.5, step=dd.FixedStep(1e-3), output_dt=0.01)
    assert res.success
    # index-3 generalized-alpha satisfies the constraint on positions; velocities carry an
    # O(h^2) = 1e-6 relative error, which the damper torque (and so the driver's) inherits
    assert res.final("drive.torque") == pytest.approx(c * w, rel=1e-5)
    assert res.final("d0.angular_velocity")[2] == pytest.approx(w, rel=1e-5)
    w_in = res.final("energy.work_in")
    assert w_in == pytest.approx(res.final("energy.dissipated") + 0.5 * J1 * w**2, rel=1e-3)


def test_angle_driver_follows_its_function_over_many_revolutions():
    """Angle driver with a ramp through 20 revolutions: the accumulated joint angle follows
    the function (no wrap-around at pi), and the torque is J alpha during the ramp."""
    spec = disks(1)
    turns = 20 * 2 * np.pi
    spec.add(dd.JointDriver("drive", "h0", dd.SmoothStep(0.0, 1.0, 0.0, turns),
                            quantity="angle"))
    res = dd.simulate(dd.compile_model(spec), 1.2, step=dd.FixedStep(5e-4), output_dt=0.05)
    f = dd.SmoothStep(0.0, 1.0, 0.0, turns)
    np.testing.assert_allclose(res["drive.angle"].values, f(res.time), atol=1e-7)
    np.testing.assert_allclose(res["h0.angle"].values, f(res.time), atol=1e-7)
    # torque = J * f''(t); second-order accurate, h^2 f'''' tiny here, 1e-3 relative is ample
    i = np.searchsorted(res.time, 0.2)
    assert res["drive.torque"].values[i] == pytest.approx(J1 * f.second_derivative(0.2),
                                                          rel=1e-3)


def test_speed_difference_driver_splits_torque_by_inertia():
    """Disk 0 driven by T0, disk 1 free, their speed difference held at w: both accelerate
    at T0 / (J1 + J2) and the driver carries -J2 T0 / (J1 + J2) on disk 0."""
    T0, w = 2.0, 5.0
    spec = disks(2)
    spec.add(dd.Torque("T", "m0", vector=(0.0, 0.0, T0)))
    spec.add(dd.SpeedDifferenceDriver("diff", "h0", "h1", w))
    model = dd.compile_model(spec)
    st = model.initial_state()
    st.v[5] = w  # start on the prescribed difference
    res = dd.simulate(model, 0.3, state=st, step=dd.FixedStep(1e-3), output_dt=0.05)
    assert res.success
    om0 = res["d0.angular_velocity"].values[:, 2]
    om1 = res["d1.angular_velocity"].values[:, 2]
    np.testing.assert_allclose(om0 - om1, w, atol=1e-9)
    alpha = T0 / (J1 + J2)
    np.testing.assert_allclose(om1, alpha * res.time, rtol=1e-9, atol=1e-12)
    assert res.final("diff.torque") == pytest.approx(-J2 * T0 / (J1 + J2), rel=1e-9)
    # energy: work of T and of the driver equals the kinetic energy gained; the driver's
    # torque on disk 0 and its reaction on disk 1 do net work tau * (w0 - w1) = tau * w
    assert abs(res.final("energy.balance_error")) < 1e-6 * res.final("energy.kinetic")
    tau = -J2 * T0 / (J1 + J2)
    assert res.final("energy.work_drivers") == pytest.approx(tau * w * 0.3, rel=1e-6)
    assert res.final("energy.work_loads") == pytest.approx(
        T0 * (w * 0.3 + 0.5 * alpha * 0.3**2), rel=1e-6)


def test_variables_filter_keeps_the_requested_sensors():
    spec = disks(1)
    spec.add(dd.Torque("T", "m0", vector=(0.0, 0.0, 1.0)))
    res = dd.simulate(dd.compile_model(spec), 0.01, step=dd.FixedStep(1e-3),
                      variables=["d0.angular_velocity", "*.torque_z"])
    names = set(res.dataset.data_vars)
    assert {"d0.angular_velocity", "h0.torque_z", "energy.balance_error"} <= names
    assert "d0.position" not in names and "T.power" not in names


def slider(m: float = 2.0) -> dd.Spec:
    """A block of mass ``m`` on a prismatic joint along the inclined axis (1, 2, 2)/3,
    offset 0.3 m along it from the guide's marker."""
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    spec = dd.Spec()
    spec.add_rigid_body("block", m, [0.01, 0.01, 0.01], position=0.3 * axis)
    spec.add_marker("guide", "ground", axis=axis)
    spec.add_marker("slide", "block", axis=axis)
    spec.add(dd.Prismatic("rail", "guide", "slide"))
    return spec


def test_travel_driver_follows_its_function_and_reports_the_force():
    """A block on an inclined rail moved by s(t) = 0.2 sin(5 t) from its initial 0.3 m: the
    slide follows the function from its initial value, and the driver's force on the block
    along the axis is m s''. Fails if the slide is measured from 0 instead of its initial
    value, or the force is reported with the opposite sign."""
    m = 2.0
    spec = slider(m)
    t_tab = np.linspace(0.0, 1.0, 2001)
    f = dd.Table(t_tab, 0.2 * np.sin(5.0 * t_tab))
    spec.add(dd.TravelDriver("actuator", "rail", f))
    res = dd.simulate(dd.compile_model(spec), 0.6, step=dd.FixedStep(5e-4), output_dt=0.05)
    assert res.success
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    slide = res["block.position"].values @ axis
    np.testing.assert_allclose(slide, 0.3 + 0.2 * np.sin(5.0 * res.time), atol=1e-6)
    i = np.searchsorted(res.time, 0.3)
    # piecewise-linear table: the driver holds the table, whose acceleration is the sine's
    # within (h_table w)^2 / 12 relative
    assert res["actuator.force"].values[i] == pytest.approx(
        -m * 0.2 * 25.0 * np.sin(5.0 * res.time[i]), rel=2e-3)


def test_travel_speed_driver_and_static_force():
    """Speed mode: s - s0 is the integral of the speed (0.1 m/s for 0.5 s: 0.05 m). In a
    static equilibrium against a spring of rate k along the rail the driver carries k s.
    Fails if the speed is not integrated or the force is not the multiplier."""
    k = 4.0e3
    spec = slider()
    spec.add_marker("anchor", "ground", position=(0.0, 0.0, 0.0))
    spec.add_marker("hook", "block")
    spec.add(dd.SpringDamper("spring", "anchor", "hook", stiffness=k, free_length=0.3))
    spec.add(dd.TravelDriver("actuator", "rail", dd.Ramp(0.5, 0.5001, 0.1, 0.0),
                             quantity="speed"))
    model = dd.compile_model(spec)
    st = dd.solve_static(model, t=1.0)
    s = st.x[0] @ (np.array([1.0, 2.0, 2.0]) / 3.0)
    integral = 0.1 * 0.5 + 0.5 * 0.1 * 1e-4  # the speed ramps to zero over 0.1 ms
    assert s == pytest.approx(0.3 + integral, rel=1e-9)
    out = dd.element_outputs(model, st)
    assert out["actuator"]["force"] == pytest.approx(k * integral, rel=1e-9)


def test_driver_kinds_are_checked():
    """An angle driver on a prismatic joint names the TravelDriver; a travel driver on a
    hinge is refused; a bad quantity names the key and value."""
    spec = slider()
    spec.add(dd.JointDriver("turn", "rail", 0.0, quantity="angle"))
    with pytest.raises(dd.ModelError, match="TravelDriver"):
        dd.compile_model(spec)
    spec = disks(1)
    spec.add(dd.TravelDriver("push", "h0", 0.0))
    with pytest.raises(dd.ModelError, match="sliding axis"):
        dd.compile_model(spec)
    with pytest.raises(dd.ModelError, match=r"quantity.*'angle'"):
        dd.TravelDriver("push", "rail", 0.0, quantity="angle").validate()
