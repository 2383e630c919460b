"""The bushing element: tangents with a committed branch state, the static curve, the dynamic
stiffness against the closed form of its branch network, objectivity and the balance of
forces and moments, the energy account, model files and bad input.

The tangent matrices of every configuration in ``element_cases/bushings.py`` (linear,
tabulated with preload, Maxwell branches, markers apart, ground) are also checked by the
registry test (``tests/elements/test_tangents.py``).
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.config import ModelFileError, load_model
from drivedyn.elements.bushing import (
    Bushing,
    BushingCurve,
    BushingRotationalCurve,
    MaxwellBranch,
    RotationalMaxwellBranch,
)
from drivedyn.elements.framework.contract import MODE_DYN
from drivedyn.errors import ModelError
from drivedyn.model import Spec, compile_model
from drivedyn.rotations import exp_so3
from drivedyn.solver.system import System
from drivedyn.validation import bushings as VB  # noqa: N812
from drivedyn.validation.integrator import energy_scale
from element_cases.bushings import offset_case
from fdcheck import check_tangents

# everything on: linear x, y and rotations, a curve on z and on rx, branches on x, z, ry
FULL = dict(
    stiffness=(2.0e4, 3.0e4, 0.0), damping=(20.0, 15.0, 30.0),
    rotational_stiffness=(0.0, 200.0, 400.0), rotational_damping=(0.3, 0.2, 0.1),
    preload=(5.0, -3.0, 8.0), rotational_preload=(1.0, 0.5, -2.0),
    curves=(BushingCurve("z", (-0.02, -0.005, 0.0, 0.004, 0.012),
                         (-900.0, -120.0, 10.0, 250.0, 800.0)),),
    rotational_curves=(BushingRotationalCurve("x", (-0.06, 0.0, 0.03, 0.05),
                                              (-30.0, 2.0, 8.0, 25.0)),),
    branches=(MaxwellBranch("x", 1.0e4, 80.0), MaxwellBranch("z", 8.0e3, 150.0)),
    rotational_branches=(RotationalMaxwellBranch("y", 100.0, 2.0),),
)


def _node_pair(**kw) -> Spec:
    """Two massless nodes joined by a bushing with markers off their origins and rotated:
    the residual is the bushing's alone."""
    spec = Spec()
    spec.add_node("A", position=(0.1, -0.2, 0.3), rotation=exp_so3(np.array([0.3, -0.5, 0.8])))
    spec.add_node("B", position=(0.4, 0.1, 0.2), rotation=exp_so3(np.array([-0.7, 0.2, 0.4])))
    RA = spec.nodes["A"].rotation
    RB = spec.nodes["B"].rotation
    target = np.array([0.25, -0.05, 0.35])
    spec.add_marker("mA", "A", position=RA.T @ (target - spec.nodes["A"].position),
                    rotation=exp_so3(np.array([0.2, 0.9, -0.3])))
    spec.add_marker("mB", "B", position=RB.T @ (target - spec.nodes["B"].position + 0.02),
                    rotation=exp_so3(np.array([-0.4, 0.1, 0.6])))
    spec.add(Bushing("bu", "mA", "mB", **kw))
    return spec


def _bushing_residual(model, st) -> np.ndarray:
    sys = System(model)
    sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
    return sys.r[: model.nd].copy()


def _deflected(model, rng, scale=1.0):
    st = model.initial_state()
    st.x[: model.nn] += scale * 5e-3 * rng.standard_normal((model.nn, 3))
    for i in range(model.nn):
        st.R[i] = st.R[i] @ exp_so3(scale * 0.03 * rng.standard_normal(3))
    st.v[:] = rng.standard_normal(model.nd)
    st.t = 0.37
    return st


def test_tangents_with_a_committed_branch_state():
    """Stiffness and damping against central differences at a state whose branches carry a
    committed deflection ``s_n`` and whose committed deflections ``x_n`` and time ``t_n``
    differ from the evaluation's (the registry test starts from zero). Fails if the tangent
    takes the branch stiffness as ``k_b`` instead of ``k_b phi`` or reads the wrong state
    slot."""
    model = compile_model(offset_case())
    rng = np.random.default_rng(5)
    st = _deflected(model, rng)
    g, _ = model.group("bu")
    o = g.eoff[0]
    st.es[o] = 0.21  # t_n
    st.es[o + 1:o + 7] = 1e-3 * rng.standard_normal(6)  # x_n
    st.es[o + 7:o + 7 + 5] = 1e-3 * rng.standard_normal(5)  # s_n of the five branches
    assert g.nstate == 1 + 6 + 5
    check_tangents(model, st)


def test_branch_update_is_exact_for_a_linear_deflection_history():
    """Between the committed state and the evaluation the branch deflection solves
    ``s' = xdot - s / tau`` exactly for a deflection linear in time: compared with the
    closed-form solution ``s = tau v (1 - E) + E s_n`` (v the deflection rate) for several
    ``h / tau`` from 1e-9 to 50, the force of one branch on a translational axis. Fails with a
    backward-Euler update or with phi and E swapped."""
    k, c = 2.0e4, 50.0
    tau = c / k
    model = compile_model(_node_pair(branches=(MaxwellBranch("y", k, c),)))
    g, _ = model.group("bu")
    o = g.eoff[0]
    ref = model.initial_state()
    for r in (1e-9, 1e-3, 0.5, 3.0, 50.0):
        h = r * tau
        st = ref.copy()
        xn, sn, vel = 2e-4, -3e-5, 0.05  # committed deflection, branch deflection, rate
        st.es[o] = 1.0
        st.es[o + 2] = xn
        st.es[o + 7] = sn
        st.t = 1.0 + h
        # move node B so that the y deflection (bushing frame) is xn + vel h
        RA = ref.R[model.node_index["A"]] @ model.marker_frames["mA"][2]
        b = model.node_index["B"]
        st.x[b] = ref.x[b] + RA[:, 1] * (xn + vel * h)
        _bushing_residual(model, st)
        E = math.exp(-r)
        s_exact = tau * vel * (1.0 - E) + E * sn
        assert g.aux[0, 7] == pytest.approx(xn + vel * h, rel=1e-12, abs=1e-15)
        assert g.aux[0, 1] == pytest.approx(k * s_exact, rel=1e-9, abs=1e-12)


def test_objectivity_rigid_motion_gives_no_force():
    """A rigid motion of the whole bushing (both nodes rotated by 120 deg about an oblique
    axis through a point off the bushing, translated, and spinning together about another
    axis) changes no deflection, no deflection rate and no force: the outputs stay at the
    preload and the residual rotates with the pair. Fails if the deflection were measured in
    the global frame or the rotation as the difference of rotation vectors, or if the
    damper saw the rigid spin."""
    model = compile_model(_node_pair(**FULL))
    g, _ = model.group("bu")
    st0 = model.initial_state()
    r0 = _bushing_residual(model, st0)
    out0 = g.aux[0, :13].copy()
    np.testing.assert_allclose(out0[6:12], 0.0, atol=1e-15)  # undeflected at the start
    Q = exp_so3(np.radians(120.0) * np.array([1.0, 2.0, -1.0]) / math.sqrt(6.0))
    c = np.array([1.0, -2.0, 0.5])
    w = np.array([3.0, -1.0, 2.0])  # common spin [rad/s]
    st = st0.copy()
    for i in range(model.nn):
        st.x[i] = c + Q @ (st0.x[i] - c) + np.array([0.3, 0.2, -0.1])
        st.R[i] = Q @ st0.R[i]
        st.v[6 * i:6 * i + 3] = np.cross(w, st.x[i] - c)
        st.v[6 * i + 3:6 * i + 6] = st.R[i].T @ w
    r = _bushing_residual(model, st)
    out = g.aux[0, :13]
    np.testing.assert_allclose(out[6:12], 0.0, atol=1e-14)  # no deflection
    np.testing.assert_allclose(out[:6], out0[:6], rtol=1e-12, atol=1e-9)  # preload only
    assert abs(out[12]) < 1e-18  # nothing dissipated: no deflection rate
    for i in range(model.nn):  # forces global (rotate), moments in the node frame (same)
        np.testing.assert_allclose(r[6 * i:6 * i + 3], Q @ r0[6 * i:6 * i + 3], atol=1e-9)
        np.testing.assert_allclose(r[6 * i + 3:6 * i + 6], r0[6 * i + 3:6 * i + 6], atol=1e-9)


def test_deflected_bushing_is_objective_and_balanced():
    """At a deflected, moving state: (1) the outputs (forces, moments, deflections,
    dissipated power) do not change when the whole state is rotated rigidly; (2) the forces
    on A and B are equal and opposite and the moments balance about any point, the moment of
    the force about the lever arm between the markers included. Fails if the moment of the
    force on node A took the arm of marker A instead of marker B (the reaction then leaves
    a couple), or if the rotation rows forgot the tangent operator."""
    model = compile_model(_node_pair(**FULL))
    g, _ = model.group("bu")
    rng = np.random.default_rng(3)
    st = _deflected(model, rng)
    r = _bushing_residual(model, st)
    out = g.aux[0, :13].copy()
    assert np.abs(out[6:9]).max() > 1e-3 and np.abs(out[9:12]).max() > 1e-2
    assert np.abs(out[:6]).max() > 10.0
    # balance: sum of forces, moments about P (global), residual = internal forces
    F = r[0:3] + r[6:9]
    scale = np.abs(r).max()
    np.testing.assert_allclose(F, 0.0, atol=1e-12 * scale)
    for P in (np.zeros(3), np.array([5.0, -3.0, 2.0])):
        M = sum(np.cross(st.x[i] - P, r[6 * i:6 * i + 3]) + st.R[i] @ r[6 * i + 3:6 * i + 6]
                for i in range(2))
        np.testing.assert_allclose(M, 0.0, atol=1e-12 * scale * (1 + np.linalg.norm(P)))
    # the same state rotated rigidly: same outputs
    Q = exp_so3(np.array([0.7, -1.1, 0.4]))
    st2 = st.copy()
    for i in range(model.nn):
        st2.x[i] = Q @ st.x[i]
        st2.R[i] = Q @ st.R[i]
        st2.v[6 * i:6 * i + 3] = Q @ st.v[6 * i:6 * i + 3]
    _bushing_residual(model, st2)
    np.testing.assert_allclose(g.aux[0, :13], out, rtol=1e-10, atol=1e-12)


def test_static_curve_from_a_quasi_static_sweep():
    """The validation case's sweep of a tabulated axis (no damping) from 0 down to -6 mm and
    up to +5 mm, beyond both ends of the table: the force is the table's value at its points
    and SciPy's PCHIP of the table between them, the end tangents beyond (linear
    extrapolation). Fails with a linear interpolation between the points or with constant
    extrapolation."""
    xs, fs = (np.asarray(a) for a in VB.STATIC_TABLE)
    x, F, res = VB.static_sweep(quick=True)
    assert res.success
    assert x.min() < xs[0] - 1e-3 and x.max() > xs[-1] + 1e-3
    np.testing.assert_allclose(F, VB.pchip_reference(xs, fs, x), rtol=0, atol=1e-9 * 9000.0)
    for xi, fi in zip(xs, fs, strict=True):
        i = int(np.argmin(np.abs(x - xi)))
        assert abs(x[i] - xi) < 1e-12
        assert F[i] == pytest.approx(fi, abs=1e-9)
    beyond = x > xs[-1]
    slope = np.diff(F[beyond]) / np.diff(x[beyond])
    np.testing.assert_allclose(slope, slope[0], rtol=1e-9)


def test_static_equilibrium_on_a_rotational_curve_with_preload():
    """A wheel on a hinge held by a bushing whose rotation about the hinge axis follows a
    tabulated curve plus a preload, loaded by a torque: the static equilibrium angle solves
    ``curve(theta) + preload = T``, inside the table and on its linear extension. Fails if the
    preload were not added or the curve's slope extrapolated constant."""
    from drivedyn.elements.framework.curves import curve_value, pack_curves
    from drivedyn.elements.joints import Hinge
    from drivedyn.elements.loads import Torque
    from drivedyn.solver import solve_static

    xs, ys = (-0.1, -0.02, 0.0, 0.05, 0.2), (-300.0, -40.0, 5.0, 60.0, 400.0)
    pre = 7.0
    X, Y, D, start = pack_curves([(np.asarray(xs), np.asarray(ys))])
    for T in (30.0, 500.0, -350.0):  # inside, beyond the upper and the lower end
        spec = Spec()
        spec.add_rigid_body("wheel", 1.0, [0.1, 0.1, 0.1])
        spec.add_marker("g", "ground", axis=(0.0, 1.0, 0.0))
        spec.add_marker("w", "wheel", axis=(0.0, 1.0, 0.0))
        spec.add(Hinge("h", "g", "w"))
        # bushing frame: x along the hinge axis (global y)
        Rb = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        spec.add_marker("seat", "ground", rotation=Rb)
        spec.add_marker("sleeve", "wheel", rotation=Rb)
        spec.add(Bushing("bu", "seat", "sleeve", rotational_preload=(pre, 0.0, 0.0),
                         rotational_curves=(BushingRotationalCurve("x", xs, ys),)))
        spec.add(Torque("load", "w", vector=(0.0, T, 0.0)))
        model = compile_model(spec)
        st = solve_static(model)
        g, _ = model.group("bu")
        th = g.aux[0, 9]
        assert curve_value(X, Y, D, start, 0, th)[0] + pre == pytest.approx(T, rel=1e-9)
        assert g.aux[0, 3] == pytest.approx(T, rel=1e-9)
        assert np.abs(st.R[model.node_index["wheel"]] @ np.array([1.0, 0.0, 0.0])
                      - np.array([math.cos(th), 0.0, -math.sin(th)])).max() < 1e-9


@pytest.mark.parametrize("kind", ["translation", "rotation"])
def test_dynamic_stiffness_and_energy_per_cycle(kind):
    """Sinusoidal deflection at 1, 10 and 50 Hz (a driver on one marker, the other on the
    ground) of an axis with a Kelvin-Voigt part and two Maxwell branches: |K*| and the loss
    angle from the first harmonics of the steady-state force and deflection against the
    closed form ``k0 + i w c0 + sum k_b i w tau_b/(1 + i w tau_b)`` within 1e-3 (the
    requirement is 1 %, measured 1e-5 .. 2e-4), the energy dissipated over a period against
    ``pi X^2 Im K*``. Fails with a backward-Euler branch update (first order: loss angles
    1.4 % low at 10 Hz, 200 steps per period), with tau_b taken as k_b/c_b, or with the
    damper on the deflection instead of its rate."""
    for f in VB.FREQUENCIES:
        hr = VB.harmonic_response(kind, f)
        assert hr.res.success
        assert abs(abs(hr.k_sim) / abs(hr.k_ref) - 1.0) < 1e-3, (f, hr.k_sim, hr.k_ref)
        assert abs(np.angle(hr.k_sim) / np.angle(hr.k_ref) - 1.0) < 1e-3, (f, hr.k_sim,
                                                                          hr.k_ref)
        assert hr.energy_sim == pytest.approx(hr.energy_ref, rel=1e-3)
        # the network is not trivial at this frequency: the branches' share of K*
        kb = hr.k_ref - VB.branch_bushing(kind).dynamic_stiffness(
            "z" if kind == "translation" else "x", 0.0, kind == "rotation")
        assert abs(kb) > 0.005 * abs(hr.k_ref)


def test_validation_case_passes():
    """``drivedyn validate --case bushing_dynamic_stiffness --quick``: every check passes."""
    from drivedyn.validation import CASES

    results = CASES["bushing_dynamic_stiffness"](quick=True)
    assert len(results) == 2 * 3 * 3 + 2
    assert all(r.passed for r in results), [(r.quantity, r.error) for r in results
                                            if not r.passed]


def test_energy_balance_of_a_damped_free_vibration():
    """A body on a bushing with every feature (linear axes, curves, preload, dampers,
    Maxwell branches) released with a velocity and a spin: kinetic + potential energy minus
    the energy dissipated stays constant to 1e-3 of the energy exchanged, and most of the
    initial energy is dissipated. Fails if the branches' potential energy
    ``k_b s_b^2 / 2`` or their dissipation ``k_b^2 s_b^2 / c_b`` were left out of the
    account, or if the potential of a curve were the linear spring's."""
    spec = Spec()
    spec.add_rigid_body("body", 2.0, [0.02, 0.03, 0.025], com=(0.01, 0.0, -0.02),
                        velocity=(0.2, -0.1, 0.3), angular_velocity=(2.0, 1.0, -1.5))
    spec.add_marker("seat", "ground", rotation=exp_so3(np.array([0.2, -0.1, 0.3])))
    spec.add_marker("sleeve", "body", position=(0.05, 0.0, 0.0))
    spec.add(Bushing("bu", "seat", "sleeve", **FULL))
    model = compile_model(spec)
    res = dd.simulate(model, 1.0, step=dd.FixedStep(2e-4), output_dt=2e-3)
    assert res.success
    scale = energy_scale(res)
    err = np.abs(res["energy.balance_error"].values).max() / scale
    assert err < 1e-3, err
    D = res["bu.dissipated_energy"].values[-1]
    assert D > 0.3 * res["energy.kinetic"].values[0]


def _file(tmp_path, elements: str, name: str = "b.toml"):
    text = textwrap.dedent("""
        [model]
        name = "bushing"

        [[bodies]]
        name = "block"
        mass = "2 kg"
        inertia = [0.1, 0.1, 0.1]

        [[markers]]
        name = "seat"
        body = "ground"

        [[markers]]
        name = "sleeve"
        body = "block"
    """) + textwrap.dedent(elements)
    p = tmp_path / name
    p.write_text(text)
    return p


MOUNT = """
    [[elements]]
    type = "Bushing"
    name = "mount"
    marker_a = "seat"
    marker_b = "sleeve"
    stiffness = ["20 kN/mm", "20 kN/mm", 0]
    damping = [200, 200, "0.3 kN s/m"]
    rotational_stiffness = ["1 kN m/rad", "1 kN m/rad", "500 N m/rad"]
    preload = [0, 0, "-50 N"]

    [[elements.curves]]
    axis = "z"
    deflection = ["-4 mm", "-2 mm", 0, "1 mm", "3 mm"]
    force = ["-9 kN", "-3.5 kN", "200 N", "1.8 kN", "8 kN"]

    [[elements.branches]]
    axis = "z"
    stiffness = "400 N/mm"
    damping = "400 N s/m"

    [[elements.rotational_branches]]
    axis = "x"
    stiffness = "300 N m/rad"
    damping = "0.6 N m s/rad"
"""


def test_model_file_syntax_and_units(tmp_path):
    """The ``[[elements]]`` syntax of the docs: 3-vectors and tables with unit strings,
    curves and branches as arrays of tables, converted to SI; the same bushing as built in
    Python. Fails if a unit of a table or a branch were not converted."""
    model = load_model(_file(tmp_path, MOUNT))
    g, _ = model.group("mount")
    kx, cx, pre, cid, CX, CY = (g.params[i] for i in (5, 6, 7, 8, 9, 10))
    np.testing.assert_allclose(kx[0], [2e7, 2e7, 0.0, 1e3, 1e3, 500.0])
    np.testing.assert_allclose(cx[0], [200.0, 200.0, 300.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(pre[0], [0.0, 0.0, -50.0, 0.0, 0.0, 0.0])
    assert list(cid[0]) == [-1, -1, 0, -1, -1, -1]
    np.testing.assert_allclose(CX, [-4e-3, -2e-3, 0.0, 1e-3, 3e-3])
    np.testing.assert_allclose(CY, [-9e3, -3.5e3, 200.0, 1.8e3, 8e3])
    baxis, bk, bc = g.params[13:16]
    assert list(baxis[0]) == [2, 3]
    np.testing.assert_allclose(bk[0], [4e5, 300.0])
    np.testing.assert_allclose(bc[0], [400.0, 0.6])
    spec = model.spec.element("mount")
    assert spec.dynamic_stiffness("z", 10.0).real > 0.0


@pytest.mark.parametrize(("edit", "message"), [
    (('deflection = ["-4 mm"', 'deflection = ["-4 N"'),
     r"elements\[0\] \(mount\).curves\[0\].deflection"),
    (('stiffness = "400 N/mm"', 'stiffness = "400 N m/rad"'),
     r"elements\[0\] \(mount\).branches\[0\].stiffness"),
    (('"1.8 kN", "8 kN"', '"1.8 kN", "1 kN"'),
     r"elements\[0\] \(mount\).curves\[0\]: values must not decrease .*1800.0 at 0.001 then "
     r"1000.0 at 0.003"),
    (('stiffness = ["20 kN/mm", "20 kN/mm", 0]', 'stiffness = ["20 kN/mm", -5, 0]'),
     r"elements\[0\] \(mount\).stiffness\[1\]: must be >= 0 N/m, got -5"),
    (('stiffness = ["20 kN/mm", "20 kN/mm", 0]', 'stiffness = ["20 kN/mm", "20 kN/mm", 10]'),
     r"elements\[0\] \(mount\).stiffness\[2\]: must be 0 on axis 'z', which has a curve "
     r"\(curves\[0\]\), got 10"),
    (('axis = "x"', 'axis = "w"'),
     r"elements\[0\] \(mount\).rotational_branches\[0\].axis: expected 'x', 'y' or 'z', got "
     r"'w'"),
])
def test_bad_model_files_name_the_key_and_value(tmp_path, edit, message):
    """A unit of another dimension in a table or a branch, a decreasing table, a negative
    stiffness, a stiffness on an axis with a curve, an unknown axis: ModelFileError naming
    the entry, the key and the value."""
    text = MOUNT.replace(*edit)
    assert text != MOUNT
    with pytest.raises(ModelFileError, match=message):
        load_model(_file(tmp_path, text))


@pytest.mark.parametrize(("kw", "message"), [
    (dict(curves=(BushingCurve("y", (-1e-3, 0.0, 1e-3), (-100.0, 50.0, 20.0)),)),
     r"Bushing 'b'.curves\[0\]: values must not decrease \(a monotone curve\), got 50.0 at "
     r"0.0 then 20.0 at 0.001"),
    (dict(curves=(BushingCurve("y", (-1e-3, 1e-3, 0.0), (-100.0, 0.0, 20.0)),)),
     r"Bushing 'b'.curves\[0\]: abscissae must increase strictly, got 0.001 then 0.0"),
    (dict(rotational_curves=(BushingRotationalCurve("z", (0.0, math.nan), (0.0, 1.0)),)),
     r"Bushing 'b'.rotational_curves\[0\].angle\[1\]: must be finite \[rad\], got nan"),
    (dict(curves=(BushingCurve("x", (0.0,), (1.0,)),)),
     r"Bushing 'b'.curves\[0\]: a table needs at least 2 points, got 1"),
    (dict(stiffness=(1.0, -2.0, 0.0)), r"Bushing 'b'.stiffness\[1\]: must be >= 0 N/m, got -2.0"),
    (dict(rotational_damping=(math.nan, 0.0, 0.0)),
     r"Bushing 'b'.rotational_damping\[0\]: must be >= 0 N m s/rad, got nan"),
    (dict(preload=(0.0, math.inf, 0.0)),
     r"Bushing 'b'.preload\[1\]: must be finite \[N\], got inf"),
    (dict(damping=(1.0, 2.0)), r"Bushing 'b'.damping: expected 3 numbers \[N s/m\]"),
    (dict(branches=(MaxwellBranch("x", 1e4, 0.0),)),
     r"Bushing 'b'.branches\[0\].damping: must be > 0 N s/m, got 0.0"),
    (dict(rotational_branches=(RotationalMaxwellBranch("y", -3.0, 1.0),)),
     r"Bushing 'b'.rotational_branches\[0\].stiffness: must be > 0 N m/rad, got -3.0"),
    (dict(curves=(BushingCurve("x", (0.0, 1.0), (0.0, 1.0)),
                  BushingCurve("x", (0.0, 1.0), (0.0, 2.0)))),
     r"Bushing 'b'.curves\[1\].axis: a second curve for axis 'x'"),
])
def test_bad_parameters_name_the_key_and_value(kw, message):
    """Non-monotone or unordered tables, NaN and infinite values, negative stiffness, a
    branch without damping, a second curve on an axis: ModelError naming the element, the
    key (with the index) and the value, in the parameter's unit."""
    with pytest.raises(ModelError, match=message):
        Bushing("b", "seat", "sleeve", **kw).validate()
