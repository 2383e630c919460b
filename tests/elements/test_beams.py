"""The geometrically exact beam: SE(3) operators, builders, model files, results, plots,
the validation cases and the convergence order of the element.

The tangent of the element is checked against finite differences by the registry test
(``tests/elements/test_tangents.py``, cases in ``element_cases/beams.py``).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from click.testing import CliRunner

import drivedyn as dd
from drivedyn.cli import main as cli
from drivedyn.elements.beams.kernel import section_forces, section_tangent
from drivedyn.elements.beams.se3 import (
    exp_se3,
    log_se3,
    tangent_inv_coeff_rate,
    tangent_inv_coeffs,
    tangent_inv_se3,
    tangent_inv_se3_rate,
)
from drivedyn.validation import base
from drivedyn.validation.beams import cantilever, load_steps, timoshenko_tip_deflection

BEAM_CASES = ("beam_rollup", "beam_cantilever_tip", "beam_eigenfrequencies",
              "beam_large_deflection", "beam_energy", "shaft_torsional_mode")


# -- SE(3) -----------------------------------------------------------------------------------


@pytest.mark.parametrize("scale", [1e-3, 0.5, 1.5, 3.0])
def test_se3_tangent_inverse_is_the_derivative_of_log(scale):
    """exp(d + delta) = exp(d) exp(T(d) delta): the inverse tangent equals the derivative of
    log(exp(d)^-1 exp(d + delta)) with respect to delta (central differences), for rotation
    angles from 1e-3 rad (series branch) to beyond 1 rad (closed form)."""
    rng = np.random.default_rng(3)
    d = rng.standard_normal(6) * scale
    Ti = np.zeros((6, 6))
    tangent_inv_se3(d, 1.0, Ti, np.zeros((3, 3)), np.zeros((3, 3)))
    x0, R0 = exp_se3(d)
    J = np.zeros((6, 6))
    h = 1e-6
    for j in range(6):
        lp, lm = np.zeros(6), np.zeros(6)
        dp, dm = d.copy(), d.copy()
        dp[j] += h
        dm[j] -= h
        log_se3(x0, R0, *exp_se3(dp), lp)
        log_se3(x0, R0, *exp_se3(dm), lm)
        J[:, j] = (lp - lm) / (2 * h)
    np.testing.assert_allclose(J, np.linalg.inv(Ti), atol=2e-9)


def test_se3_log_inverts_exp():
    rng = np.random.default_rng(4)
    for _ in range(5):
        d = rng.standard_normal(6)
        d[3:] *= 2.5 / max(np.linalg.norm(d[3:]), 1.0)  # |theta| < pi
        out = np.zeros(6)
        log_se3(np.zeros(3), np.eye(3), *exp_se3(d), out)
        np.testing.assert_allclose(out, d, atol=1e-13)


@pytest.mark.parametrize("angle", [3e-5, 0.4, 2.0, 2.5, 3.1])
def test_se3_log_rotation_is_log_so3_bit_for_bit(angle):
    """log_se3 computes the relative rotation vector with scalars (no temporaries), as
    :func:`drivedyn.rotations.log_so3` does on ``R_A^T R_B`` (``mtm``), operation for operation: the
    same bits in the three regimes (the series below 1e-4 rad, the skew part, and beyond
    134 deg, where it calls log_so3). It fails if the scalar transcription reorders an
    operation (the trace summed in the other order: seen failing at 0.4 rad)."""
    from drivedyn.elements.framework.primitives import mtm
    from drivedyn.rotations import exp_so3, log_so3

    rng = np.random.default_rng(11)
    for _ in range(20):
        RA = exp_so3(rng.standard_normal(3))
        n = rng.standard_normal(3)
        RB = RA @ exp_so3(angle * n / np.linalg.norm(n))
        out = np.zeros(6)
        log_se3(rng.standard_normal(3), RA, rng.standard_normal(3), RB, out)
        Rr = np.zeros((3, 3))
        mtm(RA, RB, Rr)
        assert np.array_equal(out[3:], log_so3(Rr)), angle


def test_complex_evaluation_matches_real():
    """The complex-step derivative needs the complex path to equal the real one."""
    d = np.array([0.3, -0.2, 0.1, 0.4, 0.9, -0.7])
    T = np.zeros((6, 6))
    Tc = np.zeros((6, 6), complex)
    tangent_inv_se3(d, -1.0, T, np.zeros((3, 3)), np.zeros((3, 3)))
    tangent_inv_se3(d.astype(complex), -1.0, Tc, np.zeros((3, 3), complex),
                    np.zeros((3, 3), complex))
    np.testing.assert_array_equal(Tc.real, T)
    assert not Tc.imag.any()


def test_the_pair_of_tangent_inverses_is_two_calls_to_the_last_bit():
    """The beam's section forces take ``T_SE3^-1(d)`` and ``T_SE3^-1(-d)`` from
    ``tangent_inv_se3_pair`` (one pass, shared terms); they must be
    :func:`tangent_inv_se3`'s values bit for bit, real and complex (the complex step),
    small and large angles (series and closed form of the coefficients). Fails with the
    off-diagonal block's terms summed in another order, or a sign of ``S/2`` changed (seen)."""
    from drivedyn.elements.beams.se3 import tangent_inv_se3_pair

    rng = np.random.default_rng(2)
    for _ in range(200):
        d = rng.standard_normal(6) * 10 ** rng.uniform(-4, 0.7)
        for dt in (float, complex):
            dd = d.astype(dt)
            if dt is complex:
                dd[rng.integers(6)] += 1e-20j
            ref = [np.zeros((6, 6), dt) for _ in range(2)]
            pair = [np.zeros((6, 6), dt) for _ in range(2)]
            S, U = np.zeros((3, 3), dt), np.zeros((3, 3), dt)
            tangent_inv_se3(dd, 1.0, ref[0], S, U)
            tangent_inv_se3(dd, -1.0, ref[1], S, U)
            tangent_inv_se3_pair(dd, pair[0], pair[1], S, U)
            assert np.array_equal(pair[0], ref[0]) and np.array_equal(pair[1], ref[1])


@pytest.mark.parametrize("scale", [0.0, 1e-3, 0.4, 0.95, 1.1, 2.5])
def test_tangent_inverse_rate_is_its_complex_step(scale):
    """The closed-form derivatives of T_SE3^-1(+-d) along each component of ``d`` and the
    rate of the coefficient ``e`` equal complex steps of :func:`tangent_inv_se3` and
    :func:`tangent_inv_coeffs` to round-off, on both sides of the series / closed-form switch
    at |theta| = 1 (scale 0.95 and 1.1: |theta| about 1.6 and 1.9 with this seed; 0.4 below
    1). Flipping the sign of one ``c (E S + S E)`` term, or of ``e'``'s ``csc^2 cot`` term,
    fails it."""
    rng = np.random.default_rng(11)
    d = rng.standard_normal(6) * scale
    t2 = float(d[3:] @ d[3:])
    c, e = tangent_inv_coeffs(t2)
    ep = tangent_inv_coeff_rate(t2)
    _, ec = tangent_inv_coeffs(t2 + 1e-30j)
    assert ep == pytest.approx(ec.imag / 1e-30, rel=1e-13)
    for j in range(6):
        dP, dM = np.zeros((6, 6)), np.zeros((6, 6))
        tangent_inv_se3_rate(d, j, c, e, ep, dP, dM)
        for sign, dT in ((1.0, dP), (-1.0, dM)):
            dc = d.astype(complex)
            dc[j] += 1e-30j
            Tc = np.zeros((6, 6), complex)
            tangent_inv_se3(dc, sign, Tc, np.zeros((3, 3), complex), np.zeros((3, 3), complex))
            np.testing.assert_allclose(dT, Tc.imag / 1e-30, rtol=0, atol=1e-14)


@pytest.mark.parametrize("scale", [1e-3, 0.5, 1.5])
def test_section_tangent_is_the_complex_step_of_the_section_forces(scale):
    """The beam's closed-form stiffness ``d(fA, fB)/dd`` (material damping and section
    velocities included) equals six complex steps of :func:`section_forces`, the kernel's
    former tangent, to round-off. Dropping the ``beta`` term of ``dsig`` or the ``dTi^T
    sig`` term (the geometric stiffness) fails it."""
    rng = np.random.default_rng(5)
    d = rng.standard_normal(6) * scale
    etaA, etaB = rng.standard_normal(6), rng.standard_normal(6)
    eps0 = rng.standard_normal(6) * 1e-3
    Ks = np.array([2e8, 5e7, 6e7, 1e4, 3e4, 4e4])
    L, beta = 0.37, 2e-4
    w = [np.zeros(6) for _ in range(5)]
    TiP, TiM, S, U = np.zeros((6, 6)), np.zeros((6, 6)), np.zeros((3, 3)), np.zeros((3, 3))
    section_forces(d, etaA, etaB, L, eps0, Ks, beta, TiP, TiM, S, U, *w)
    sig = w[2]
    Dd = np.zeros((12, 6))
    section_tangent(d, etaA, etaB, L, Ks, beta, TiP, TiM, sig, np.zeros((6, 6)),
                    np.zeros((6, 6)), np.zeros(6), Dd)
    ref = np.zeros((12, 6))
    for j in range(6):
        dc = d.astype(complex)
        dc[j] += 1e-30j
        wc = [np.zeros(6, complex) for _ in range(5)]
        section_forces(dc, etaA.astype(complex), etaB.astype(complex), L,
                       eps0.astype(complex), Ks.astype(complex), beta,
                       np.zeros((6, 6), complex), np.zeros((6, 6), complex),
                       np.zeros((3, 3), complex), np.zeros((3, 3), complex), *wc)
        ref[:6, j] = wc[3].imag / 1e-30
        ref[6:, j] = wc[4].imag / 1e-30
    np.testing.assert_allclose(Dd, ref, rtol=0, atol=1e-13 * np.abs(ref).max())


# -- validation cases --------------------------------------------------------------------------


@pytest.mark.parametrize("name", BEAM_CASES)
def test_validation_case_passes(name):
    results = base.CASES[name](quick=True, figure_dir=None)
    assert results
    for r in results:
        assert r.source and 0 < r.tolerance < np.inf
    assert all(r.passed for r in results), "\n".join(
        f"{r.quantity}: ref {r.reference:.8g} sim {r.simulated:.8g} err {r.error:.3g} "
        f"tol {r.tolerance:.3g}" for r in results)


def test_tip_deflection_converges_at_second_order():
    """Tip deflection under a tip load with 2, 4, 8, 16 elements against Timoshenko theory:
    the fitted order is 2 (one-point, constant-strain element). Printed for the record."""
    L = 0.5
    sec = dd.SolidCircular(0.02)
    p = sec.properties(dd.STEEL)
    ref = timoshenko_tip_deflection(10.0, L, p.stiffness[4], p.stiffness[1])
    ns, errs = [2, 4, 8, 16], []
    for n in ns:
        spec, nodes = cantilever(n, L, sec)
        spec.add(dd.Force("P", "tip", (0, 0, 10.0), dd.Ramp(0, 1, 0, 1)))
        model = dd.compile_model(spec)
        st = load_steps(model, 1)
        errs.append(abs(st.x[model.node_index[nodes[-1]], 2] - ref) / ref)
    order = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
    print("\nelements  relative tip error\n" + "\n".join(
        f"{n:8d}  {e:.3e}" for n, e in zip(ns, errs, strict=True)) + f"\nfitted order {order:.3f}")
    assert order == pytest.approx(2.0, abs=0.02)


# -- builders and refusals ---------------------------------------------------------------------


def test_straight_beam_nodes_and_frames():
    spec = dd.Spec()
    nodes = dd.add_straight_beam(spec, "s", (0, 0, 0), (0, 0, 2.0), 4, dd.SolidCircular(0.02),
                                 dd.STEEL)
    assert nodes == [f"s.n{i}" for i in range(5)]
    np.testing.assert_allclose(spec.nodes["s.n2"].position, (0, 0, 1.0))
    # node x along the beam
    np.testing.assert_allclose(spec.nodes["s.n0"].rotation[:, 0], (0, 0, 1.0), atol=1e-15)
    assert [e.name for e in spec.elements] == [f"s.e{i}" for i in range(4)]


@pytest.mark.parametrize(("build", "message"), [
    (lambda s: dd.add_straight_beam(s, "b", (0, 0, 0), (1, 0, 0), 0, dd.SolidCircular(0.01),
                                    dd.STEEL), "n_elements"),
    (lambda s: dd.add_straight_beam(s, "b", (1, 0, 0), (1, 0, 0), 3, dd.SolidCircular(0.01),
                                    dd.STEEL), "zero length"),
    (lambda s: dd.add_straight_beam(s, "b", (0, 0, 0), (1, 0, 0), 3, dd.SolidCircular(0.01),
                                    dd.STEEL, orientation=(2, 0, 0)), "parallel"),
])
def test_builder_refusals(build, message):
    with pytest.raises(dd.ModelError, match=message):
        build(dd.Spec())


@pytest.mark.parametrize(("element", "message"), [
    (dict(node_a="a", node_b="nowhere"), "node_b: unknown node 'nowhere'"),
    (dict(node_a="a", node_b="c"), "zero-length element"),
    (dict(node_a="a", node_b="b", damping=-1.0), "damping: must be >= 0 s"),
    (dict(node_a="a", node_b="b", mass_matrix="diagonal"), "mass_matrix"),
    (dict(node_a="a", node_b="b", material=None), "material"),
])
def test_compile_refusals(element, message):
    spec = dd.Spec()
    spec.add_node("a", (0, 0, 0))
    spec.add_node("b", (1, 0, 0))
    spec.add_node("c", (0, 0, 0))
    kw = dict(section=dd.SolidCircular(0.01), material=dd.STEEL) | element
    spec.add(dd.GeometricallyExactBeam("e", **kw))
    with pytest.raises(dd.ModelError, match=message):
        dd.compile_model(spec)


# -- model files, results, plots ------------------------------------------------------------

BEAM_FILE = """
[model]
name = "cantilever"
[[materials]]
name = "steel"
E = "210 GPa"
nu = 0.3
density = "7850 kg/m^3"
[[sections]]
name = "rod"
shape = "solid_circular"
diameter = "20 mm"
material = "steel"
[[beams]]
name = "rod"
section = "rod"
start = [0, 0, 0]
end = ["0.5 m", 0, 0]
elements = 10
[[markers]]
name = "wall"
body = "ground"
[[markers]]
name = "root"
body = "rod.n0"
[[markers]]
name = "tip"
body = "rod.n10"
[[elements]]
type = "Fixed"
name = "clamp"
marker_a = "wall"
marker_b = "root"
[[elements]]
type = "Force"
name = "P"
marker = "tip"
vector = [0, 0, "10 N"]
function = { type = "smooth_step", t0 = 0.0, t1 = 0.01, v0 = 0.0, v1 = 1.0 }
[solver]
t_end = "0.02 s"
rho_inf = 0.5
step = { mode = "fixed", h = "0.2 ms" }
[output]
dt = "1 ms"
"""


def _write(tmp_path, text, name="beam.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_beam_file_matches_python_model(tmp_path):
    """The file's cantilever is the Python one: same static tip deflection."""
    model = dd.load_model(_write(tmp_path, BEAM_FILE))
    st = dd.solve_static(model, t=1.0)
    spec, nodes = cantilever(10, 0.5, dd.SolidCircular(0.02))
    spec.add(dd.Force("P", "tip", (0, 0, 10.0)))
    ref = dd.solve_static(dd.compile_model(spec))
    assert st.x[model.node_index["rod.n10"], 2] == pytest.approx(
        ref.x[dd.compile_model(spec).node_index[nodes[-1]], 2], rel=1e-12)


def test_box_section_in_a_beam_file(tmp_path):
    """``shape = "hollow_rectangular"`` with ``thickness`` builds the box of the Python API;
    a missing thickness is named."""
    box = BEAM_FILE.replace('shape = "solid_circular"\ndiameter = "20 mm"',
                            'shape = "hollow_rectangular"\nwidth_y = "30 mm"\n'
                            'height_z = "50 mm"\nthickness = "2 mm"')
    model = dd.load_model(_write(tmp_path, box))
    sec = model.spec.element("rod.e0").section
    assert sec == dd.HollowRectangular(0.03, 0.05, 0.002)
    with pytest.raises((dd.ModelFileError, dd.ModelError), match="needs thickness"):
        dd.load_model(_write(tmp_path, box.replace('thickness = "2 mm"\n', "")))


@pytest.mark.parametrize(("edit", "message"), [
    (('E = "210 GPa"', 'E = "-210 GPa"'), r"materials\[0\] \(steel\).E: must be > 0 Pa"),
    (('nu = 0.3', 'nu = 0.7'), r"materials\[0\] \(steel\).nu"),
    (('diameter = "20 mm"', 'diameter = "0 mm"'), r"sections\[0\] \(rod\).diameter: must be > 0 m"),
    (('diameter = "20 mm"', 'diameter = "20 kg"'), r"sections\[0\] \(rod\).diameter"),
    (('shape = "solid_circular"', 'shape = "tube"'), r"sections\[0\] \(rod\).shape"),
    (('diameter = "20 mm"', 'outer_diameter = "20 mm"'), "needs diameter"),
    (('section = "rod"\nstart', 'section = "bar"\nstart'), "unknown section 'bar'"),
    (('material = "steel"', 'material = "steal"'), "did you mean 'steel'"),
    (('elements = 10', 'elements = 0'), r"beams\[0\] \(rod\).elements"),
    (('end = ["0.5 m", 0, 0]', 'end = [0, 0, 0]'), "zero length"),
    (('body = "rod.n10"', 'body = "rod.n11"'), "rod.n11"),
])
def test_bad_beam_files_name_the_key(tmp_path, edit, message):
    text = BEAM_FILE.replace(*edit, 1)
    assert text != BEAM_FILE
    with pytest.raises((dd.ModelFileError, dd.ModelError), match=message):
        dd.load_model(_write(tmp_path, text))
    res = CliRunner().invoke(cli, ["run", str(tmp_path / "beam.toml"), "--out",
                                   str(tmp_path / "r.nc")])
    assert res.exit_code == 2, res.output
    assert re.search(message, res.output), res.output
    assert "Traceback" not in res.output


def test_results_hold_stresses_with_units_and_plots(tmp_path):
    res = CliRunner().invoke(cli, ["run", str(_write(tmp_path, BEAM_FILE)), "--out",
                                   str(tmp_path / "r.nc")])
    assert res.exit_code == 0, res.output
    r = dd.load_results(tmp_path / "r.nc")
    ds = r.dataset
    for name, unit in (("von_mises", "Pa"), ("normal_stress", "Pa"), ("torque", "N m"),
                       ("bending_moment_y", "N m"), ("curvature_z", "1/m")):
        var = ds[f"rod.e0.{name}"]
        assert var.attrs["units"] == unit and var.attrs["description"]
    # the outer-fibre normal stress is |N|/A + |M| r / I of the recorded section forces
    A, Iy = np.pi * 0.02**2 / 4, np.pi * 0.02**4 / 64
    N, My, Mz = (ds[f"rod.e0.{k}"].values for k in ("axial_force", "bending_moment_y",
                                                     "bending_moment_z"))
    np.testing.assert_allclose(ds["rod.e0.normal_stress"].values,
                               np.abs(N) / A + np.hypot(My, Mz) * 0.01 / Iy, rtol=1e-12)
    assert np.abs(My).max() > 1.0  # the tip load bends the rod about y
    assert "rod.n10.position" in ds and "rod.n10.rotation" in ds
    out = tmp_path / "plots"
    res = CliRunner().invoke(cli, ["plot", str(tmp_path / "r.nc"), "--stress", "rod.e0",
                                   "--shape", "--scale", "100", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert (out / "rod.e0.stress.png").stat().st_size > 10_000
    assert (out / "beams.shape.png").stat().st_size > 10_000
    res = CliRunner().invoke(cli, ["plot", str(tmp_path / "r.nc"), "--stress", "rod.e99",
                                   "--out", str(out)])
    assert res.exit_code == 2 and "rod.e99" in res.output


def test_l_frame_of_two_beams_sharing_a_node():
    """An L frame: a column (height h, clamped at its foot) and an arm (length a) share the
    corner node; a load P down at the arm's tip. Tip deflection by Timoshenko beam theory and
    the column's axial shortening: P a^3/(3 EI) + P a/(k G A) (arm) + P a^2 h / EI (the
    column bends under the constant moment P a, exact for the element) + P h / EA."""
    # P small: at 50 N the column's top moves 6 mm towards the load and the P-delta effect
    # adds 0.7 % (the element is geometrically exact); at 1 N it is 1.5e-4
    h, a, P, n = 0.8, 0.6, 1.0, 16
    sec = dd.SolidCircular(0.02)
    EA, kGA, _, _, EI, _ = sec.properties(dd.STEEL).stiffness
    spec = dd.Spec()
    col = dd.add_straight_beam(spec, "column", (0, 0, 0), (0, 0, h), n, sec, dd.STEEL)
    arm = dd.add_straight_beam(spec, "arm", (0, 0, h), (a, 0, h), n, sec, dd.STEEL,
                               node_a=col[-1])
    # the clamp's frames coincide: the ground marker takes the foot node's frame (x up)
    spec.add_marker("floor", dd.GROUND, rotation=spec.nodes[col[0]].rotation)
    spec.add_marker("foot", col[0])
    spec.add_marker("tip", arm[-1])
    spec.add(dd.Fixed("clamp", "floor", "foot"))
    spec.add(dd.Force("P", "tip", (0, 0, -P)))
    model = dd.compile_model(spec)
    st = dd.solve_static(model)
    w = -(st.x[model.node_index[arm[-1]], 2] - h)
    ref = P * a**3 / (3 * EI) + P * a / kGA + P * a**2 * h / EI + P * h / EA
    # the arm's one-point elements are stiff by 1/(4 n^2) of its bending part (-2e-4 of w)
    # and the P-delta effect adds +1.5e-4: measured -4e-5
    assert w == pytest.approx(ref, rel=2e-4)


def test_shipped_flexible_driveshaft_carries_the_final_drive_torque():
    """The shipped driveshaft model in steady running, mean over the last 12 periods of its
    Cardan speed fluctuation (twice per revolution; about 0.19 s), sampled at 0.1 ms: the
    shaft's torque at both ends equals the pinion's mesh torque (torque balance of the
    pinion; measured 1e-5 to 3.3e-4 with two step controls), and the wheel's mesh torque
    holds the 200 N m load (measured 5e-5 to 1.9e-4). Over a window that is not a whole
    number of periods, or sampled at 1 ms (the 480 Hz tooth-mesh ripple of 11 % aliases),
    the same balance varied from 1e-5 to 2e-3 with the step sequence: a mean of the shaft's
    and pinion's inertial torques, not a solver error. Fails if a beam's torque output takes
    the wrong end or sign, or the mesh torque its arm on the wrong gear."""
    res = dd.simulate(dd.load_model("flexible-driveshaft"), output_dt=1e-4)
    assert res.success, res.message
    ds = res.dataset
    t = ds["time"].values
    w = np.linalg.norm(ds["pinion.angular_velocity"].values, axis=1)
    period = np.pi / w[t >= 0.4].mean()  # Cardan fluctuation: twice per revolution
    sel = t >= t[-1] - 12 * period - 1e-12

    def mean(k):
        return float(ds[k].values[sel].mean())

    pinion = mean("final_drive.torque_a")
    for e in ("driveshaft.e0", "driveshaft.e11"):
        assert mean(f"{e}.torque") == pytest.approx(pinion, rel=1e-3)
    assert abs(mean("final_drive.torque_b")) == pytest.approx(200.0, rel=1e-3)
    # the helical mesh with friction 0.05 passes 99 % of the power: 3 |T_a| > |T_b|
    assert 0.98 < abs(mean("final_drive.torque_b")) / (3 * abs(pinion)) < 1.0


# -- sections ------------------------------------------------------------------------------------


def test_section_properties_against_hand_formulas():
    mat = dd.Material.from_nu(210e9, 0.3, 7850.0)
    nu, G = 0.3, mat.G
    p = dd.SolidCircular(0.02).properties(mat)
    A, I = np.pi * 0.01**2, np.pi * 0.02**4 / 64
    k = 6 * (1 + nu) / (7 + 6 * nu)  # Cowper: 0.8864
    np.testing.assert_allclose(p.stiffness, [210e9 * A, k * G * A, k * G * A, G * 2 * I,
                                             210e9 * I, 210e9 * I], rtol=1e-14)
    np.testing.assert_allclose(p.rotary_inertia, 7850 * np.array([2 * I, I, I]), rtol=1e-14)
    # a thin tube tends to Cowper's 2 (1 + nu) / (4 + 3 nu)
    t = dd.HollowCircular(0.1, 0.0998).properties(mat)
    A_t = np.pi * (0.05**2 - 0.0499**2)
    assert t.stiffness[1] / (G * A_t) == pytest.approx(2 * (1 + nu) / (4 + 3 * nu), rel=2e-3)
    r = dd.Rectangular(0.02, 0.04).properties(mat)
    assert r.stiffness[1] / (G * 0.02 * 0.04) == pytest.approx(10 * (1 + nu) / (12 + 11 * nu))
    assert r.stiffness[4] == pytest.approx(210e9 * 0.02 * 0.04**3 / 12, rel=1e-14)


def test_box_section_against_hand_formulas():
    """Box 60 x 140 x 3.5 mm: area and second moments of the sharp-cornered box, Bredt's
    ``J = 4 A_m^2 t / p_m``; a thin square box tends to Cowper's ``20 (1 + nu) / (48 + 39 nu)``
    (his thin-walled box with m = n = 1)."""
    mat = dd.STEEL
    b, h, t = 0.06, 0.14, 0.0035
    p = dd.HollowRectangular(b, h, t).properties(mat)
    A = b * h - (b - 2 * t) * (h - 2 * t)
    Iy = (b * h**3 - (b - 2 * t) * (h - 2 * t) ** 3) / 12
    Iz = (h * b**3 - (h - 2 * t) * (b - 2 * t) ** 3) / 12
    J = 4 * ((b - t) * (h - t)) ** 2 * t / (2 * (b + h - 2 * t))
    np.testing.assert_allclose(p.stiffness[[0, 3, 4, 5]], [mat.E * A, mat.G * J, mat.E * Iy,
                                                           mat.E * Iz], rtol=1e-14)
    assert p.mass_per_length == pytest.approx(7850 * A, rel=1e-14)
    # shear along the deep side (z) is carried by the two 140 mm walls: k near their share
    assert 0.5 < p.stiffness[2] / (mat.G * A) < 2 * h * t / A
    sq = dd.HollowRectangular(0.1, 0.1, 1e-4).properties(mat)
    nu = mat.nu
    assert sq.stiffness[1] / (mat.G * sq.area) == pytest.approx(
        20 * (1 + nu) / (48 + 39 * nu), rel=1e-3)


def test_box_section_stresses_thin_walled():
    """Box stresses: Bredt's uniform torsional shear ``T / (2 A_m t)``; under a vertical
    shear force the webs' neutral-axis value ``V Q / (2 t I_y)``; bending at the corners."""
    from drivedyn.elements.beams.section import outer_fibre_stresses

    b, h, t = 0.06, 0.14, 0.0035
    p = dd.HollowRectangular(b, h, t).properties(dd.STEEL)
    A, Iy = p.stress_params[0], p.stress_params[1]
    T = 300.0
    s, tau, vm = outer_fibre_stresses(p.stress_kind, p.stress_params, 0, 0, 0, T, 0, 0)
    assert tau == pytest.approx(T / (2 * (b - t) * (h - t) * t), rel=1e-12)
    assert s == 0.0 and vm == pytest.approx(np.sqrt(3) * tau, rel=1e-12)
    V = 5e3
    Q = (b * h**2 - (b - 2 * t) * (h - 2 * t) ** 2) / 8
    _, tau, _ = outer_fibre_stresses(p.stress_kind, p.stress_params, 0, 0, V, 0, 0, 0)
    assert tau == pytest.approx(V * Q / (2 * t * Iy), rel=1e-12)
    M = 2e3
    s, _, vm = outer_fibre_stresses(p.stress_kind, p.stress_params, 1e4, 0, 0, 0, M, 0)
    assert s == pytest.approx(1e4 / A + M * 0.5 * h / Iy, rel=1e-12) and vm == s


@pytest.mark.parametrize(("ratio", "beta", "alpha"), [(1, 0.141, 0.208), (2, 0.229, 0.246),
                                                      (10, 0.312, 0.312)])
def test_rectangle_torsion_matches_timoshenko_goodier(ratio, beta, alpha):
    from drivedyn.elements.beams.section import rectangle_torsion

    b, a, _ = rectangle_torsion(float(ratio), 1.0)
    assert round(b, 3) == beta and round(a, 3) == alpha


def test_outer_fibre_stresses_of_a_solid_shaft_in_torsion_and_bending():
    from drivedyn.elements.beams.section import outer_fibre_stresses

    d = 0.03
    p = dd.SolidCircular(d).properties(dd.STEEL)
    T, M = 120.0, 80.0
    s, tau, vm = outer_fibre_stresses(p.stress_kind, p.stress_params, 0.0, 0.0, 0.0, T, 0.0, 0.0)
    assert tau == pytest.approx(16 * T / (np.pi * d**3), rel=1e-12)
    assert vm == pytest.approx(np.sqrt(3) * tau, rel=1e-12) and s == 0.0
    s, tau, vm = outer_fibre_stresses(p.stress_kind, p.stress_params, 0.0, 0.0, 0.0, T, M, 0.0)
    sb = 32 * M / (np.pi * d**3)
    assert s == pytest.approx(sb, rel=1e-12)
    # bending peaks where the torsional shear is uniform: von Mises sqrt(sb^2 + 3 tau^2),
    # sampled on 32 points that include the peak (phi = 90 deg)
    assert vm == pytest.approx(np.hypot(sb, np.sqrt(3) * 16 * T / (np.pi * d**3)), rel=1e-12)


@pytest.mark.parametrize(("build", "message"), [
    (lambda: dd.Material.from_nu(-1.0, 0.3, 7850.0), r"material.E: must be > 0 Pa, got -1.0"),
    (lambda: dd.Material.from_nu(210e9, 0.6, 7850.0), r"material.nu"),
    (lambda: dd.Material(210e9, 81e9, 0.0), r"material.density"),
    (lambda: dd.HollowCircular(0.02, 0.02), r"inner_diameter: must be >= 0 and < outer"),
    (lambda: dd.SolidCircular(0.0), r"section.diameter: must be > 0 m, got 0.0"),
    (lambda: dd.SolidCircular(0.02).properties(None), r"material .* is required"),
    (lambda: dd.GeneralSection(1.0, 1.0, 1.0, -1.0, 1.0, 1.0, 1.0), r"section.GJ"),
    (lambda: dd.HollowRectangular(0.05, 0.1, 0.025), r"section.thickness: must be < half"),
    (lambda: dd.HollowRectangular(0.0, 0.1, 0.002), r"section.width_y: must be > 0 m"),
])
def test_section_and_material_refusals(build, message):
    with pytest.raises(dd.ModelError, match=message):
        build()


def test_general_section_stresses_need_fibre_data():
    from drivedyn.elements.beams.section import outer_fibre_stresses

    p = dd.GeneralSection(1e8, 4e7, 4e7, 1e4, 2e4, 2e4, 3.0).properties()
    assert np.isnan(outer_fibre_stresses(p.stress_kind, p.stress_params, 1e3, 0, 0, 5, 7, 0)[2])


def _loaded_rod() -> tuple[dd.Spec, float, float]:
    """A rod of 4 elements clamped at its root, a tip force across it and a torque about it;
    returns the spec and the root's bending moment [N m] and torque [N m]."""
    spec = dd.Spec()
    nodes = dd.add_straight_beam(spec, "rod", (0, 0, 0), (0.5, 0, 0), 4,
                                 dd.SolidCircular(0.02), dd.STEEL)
    spec.add_marker("wall", dd.GROUND, rotation=spec.nodes[nodes[0]].rotation)
    spec.add_marker("root", nodes[0])
    spec.add_marker("tip", nodes[-1])
    spec.add(dd.Fixed("clamp", "wall", "root"))
    spec.add(dd.Force("P", "tip", (0, 0, -50.0)))
    spec.add(dd.Torque("T", "tip", (20.0, 0, 0)))
    return spec, 50.0 * 0.5, 20.0


def test_stresses_are_computed_when_read_from_the_section_forces(tmp_path):
    """The outer-fibre stresses are derived outputs (``Group.derived``): the kernel leaves
    their columns zero (the cost this saves: 10 % of a spinning 100-element shaft's wall
    time), and every reader computes them from the section forces.

    * ``element_outputs`` at a loaded static state: ``outer_fibre_stresses`` of the
      element's forces, and non-zero (fails if it reads the kernel's columns);
    * a run recording only ``von_mises`` records the forces it needs and gives the values
      of a run recording everything (fails if the recorder's selection leaves out the
      inputs: the variable is missing);
    * the results pickled and read back (a forked bench side's way home) keep them (fails
      with a function that does not pickle, e.g. a lambda).
    """
    import pickle

    from drivedyn.elements.beams.section import outer_fibre_stresses

    spec, _, _ = _loaded_rod()
    model = dd.compile_model(spec)
    st = dd.solve_static(model)
    out = dd.element_outputs(model, st)["rod.e0"]
    g, e = model.group("rod.e0")
    assert not g.aux[:, 12:15].any()  # not computed by the kernel
    forces = [out[k] for k in ("axial_force", "shear_force_y", "shear_force_z", "torque",
                               "bending_moment_y", "bending_moment_z")]
    kind, params = g.derived.fn.args
    ref = outer_fibre_stresses(kind[e], params[e], *forces)
    assert (out["normal_stress"], out["shear_stress"], out["von_mises"]) == ref
    assert out["von_mises"] > 1e7  # 25 N m and 20 N m on a 20 mm rod: tens of MPa
    run = dict(step=dd.FixedStep(1e-4), output_dt=1e-3)
    full = dd.simulate(model, 0.005, state=st.copy(), **run)
    only = dd.simulate(model, 0.005, state=st.copy(), variables=["rod.e0.von_mises"], **run)
    assert "rod.e0.von_mises" in only and "rod.e0.torque" not in only
    back = pickle.loads(pickle.dumps(only))  # before any read: the values not yet computed
    ref = full.values("rod.e0.von_mises")
    assert ref.min() > 1e7
    np.testing.assert_array_equal(only.values("rod.e0.von_mises"), ref)
    np.testing.assert_array_equal(back.values("rod.e0.von_mises"), ref)
