"""Contact points of a flexible washer at a face quadrature: the annulus rule, the
interpolation of the mesh's fields at arbitrary points, and the element evaluated at points.

References are exact: integrals of polynomials and harmonics over the annulus, quadratic
fields (which the quadratic elements hold exactly), and the node contact (points at the face
nodes with their tributary areas are the same contact)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drivedyn.errors import ModelError
from drivedyn.fe import SolidMaterial, SolidModel, annular_washer, annulus_quadrature
from drivedyn.model.compile import compile_model
from drivedyn.solver.system import System


@pytest.mark.parametrize("cells", [1, 2])
@pytest.mark.parametrize("n_r", [1, 2, 3])
def test_annulus_rule_is_exact_for_radial_polynomials_and_harmonics_below_its_angles(n_r,
                                                                                    cells):
    """``sum w r^k = 2 pi (re^(k+2) - ri^(k+2)) / (k + 2)`` for ``k <= 2 n_r - 2`` (Gauss
    with the weight r on each interval), and the harmonics ``cos m theta``, ``sin m theta``
    sum to zero for ``1 <= m < n_theta`` while ``m = n_theta`` aliases to the area (the
    trapezoidal rule). Fails with the weight r left out of the areas (k = 0 misses the
    annulus' area) or the radii of one interval used for every cell (k = 2 with cells = 2)."""
    ri, re, nt = 0.02, 0.035, 12
    pts, w = annulus_quadrature(ri, re, 0.001, n_r, nt, cells=cells)
    assert pts.shape == (cells * n_r * nt, 3) and np.all(pts[:, 2] == 0.001)
    r = np.hypot(pts[:, 0], pts[:, 1])
    th = np.arctan2(pts[:, 1], pts[:, 0])
    for k in range(2 * n_r - 1):
        exact = 2 * math.pi * (re ** (k + 2) - ri ** (k + 2)) / (k + 2)
        assert abs(w @ r**k / exact - 1) < 1e-13, k
    area = math.pi * (re**2 - ri**2)
    for m in range(1, nt):
        assert abs(w @ np.cos(m * th)) < 1e-14 * area and abs(w @ np.sin(m * th)) < 1e-14 * area
    assert abs(w @ np.cos(nt * th) / area - 1) < 1e-12


def test_annulus_rule_refusals():
    with pytest.raises(ModelError, match="r_int < r_ext"):
        annulus_quadrature(0.03, 0.02, 0.0, 2, 12)
    with pytest.raises(ModelError, match="n_theta = 2"):
        annulus_quadrature(0.02, 0.03, 0.0, 2, 2)


@pytest.mark.parametrize("mesh", ["washer", "tetra"])
def test_interpolation_holds_quadratic_fields_at_any_point_of_the_mesh(mesh):
    """A quadratic field of the nodes, interpolated at points inside, on the faces and on the
    edges between cells (where scikit-fem's own finder misses points), equals the field;
    the rows sum to one. Fails with the cell of another point (a finder's slip) or linear
    shape functions (the quadratic term)."""
    rng = np.random.default_rng(3)
    if mesh == "washer":
        s = SolidModel(annular_washer(0.0592, 0.066, 0.002, 2, 24, 1), SolidMaterial())
        pts, _ = annulus_quadrature(0.0592, 0.066, 0.002, 3, 24, cells=2)  # vertex radii
        r = rng.uniform(0.0592, 0.066 * math.cos(math.pi / 24), 40)
        a = rng.uniform(0, 2 * math.pi, 40)
        inner = np.stack([r * np.cos(a), r * np.sin(a), rng.uniform(0, 0.002, 40)], 1)
        pts = np.vstack([pts, inner, s.nodes[::7]])
    else:
        from small_models import tet_box

        s = SolidModel(tet_box(0.1, 0.04, 3), SolidMaterial())   # [0, 0.1] x [-0.02, 0.02]^2
        pts = np.vstack([rng.uniform((0, -0.02, -0.02), (0.1, 0.02, 0.02), (60, 3)),
                         np.column_stack([rng.uniform(0, 0.1, 10), rng.uniform(-0.02, 0.02, 10),
                                          np.full(10, 0.02)]), s.nodes[::5]])

    def f(x):
        return 1.0 + 3 * x[:, 0] - x[:, 1] ** 2 + 7 * x[:, 0] * x[:, 2] + x[:, 2] ** 2

    P = s.interpolation(pts)
    assert np.allclose(P.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    assert np.allclose(P @ f(s.nodes), f(pts), rtol=0, atol=1e-12)
    assert np.allclose(P @ s.nodes, pts, rtol=0, atol=1e-15)
    with pytest.raises(ModelError, match=r"1 point\(s\) outside the mesh, first \[1.0, 0.0"):
        s.interpolation(np.vstack([pts[:2], [[1.0, 0.0, 0.0]]]))


def _washer_model(at_points: bool):
    """The registry's flexible washer case, its contact at the face nodes or at points, the
    washer mounted turned by 40 deg about its axis (the face and the law are axisymmetric)."""
    import dataclasses

    from drivedyn.rotations import exp_so3
    from element_cases.flexible import small_washer, washer_case

    spec = washer_case()
    m = spec.markers["mount"]
    spec.markers["mount"] = dataclasses.replace(
        m, rotation=m.rotation @ exp_so3(np.array([0.0, 0.0, math.radians(40.0)])))
    solid, _ = small_washer()
    if at_points:
        i = next(k for k, e in enumerate(spec.elements) if e.name == "contact")
        c = spec.elements[i]
        face = np.asarray(c.face)
        spec.elements[i] = dataclasses.replace(
            c, face=(), points=solid.nodes[face], weights=solid.face_areas(face))
    return compile_model(spec)


def test_contact_points_at_the_face_nodes_are_the_node_contact():
    """Points at the face nodes with their tributary areas evaluate the residual and the
    tangent matrices of the node contact (the basis interpolated at a node is the node's, to
    round-off). Fails with the interpolated basis left in the part frame (not turned by the
    mounting; seen) or the points' positions from another frame."""
    from fdcheck import assembled, random_state, residual

    out = []
    for at_points in (False, True):
        model = _washer_model(at_points)
        st = random_state(model, seed=11)
        sys = System(model)
        out.append((residual(sys, st), assembled(sys, st, 1.0, 0.5, 0.25)))
    (r0, A0), (r1, A1) = out
    assert np.abs(r0).max() > 1.0
    assert np.allclose(r1, r0, rtol=0, atol=1e-10 * np.abs(r0).max())
    assert np.allclose(A1, A0, rtol=0, atol=1e-10 * np.abs(A0).max())


def test_contact_points_refusals():
    from drivedyn.elements.flexible import FlexibleWasherContact

    with pytest.raises(ModelError, match="either the face nodes"):
        FlexibleWasherContact("c", "m", "f", body="w", face=(1, 2), points=[[0.0, 0.0, 0.0]],
                              weights=[1.0]).validate()
    with pytest.raises(ModelError, match="weights: expected 2 positive areas"):
        FlexibleWasherContact("c", "m", "f", body="w", points=np.zeros((2, 3)),
                              weights=[1.0, -1.0]).validate()


def test_the_differentials_default_rule_is_exact_for_a_tilted_face():
    """The TORSEN files' default contact rule (``[flexible] face_quadrature``: 2 radii per
    cell, 6 angles) on a washer pressed by a spinning face tilted by 3e-5 rad (in full
    contact, the pressure varies by about +-30 % around the washer): the friction torque and
    the washer's largest von Mises stress of 36 angles within 1e-9. Six angles integrate the
    products of the face's fields exactly up to the fifth harmonic, and a tilt times a tilt
    is the second. Fails with 3 angles (the stress +4.8 %, the torque -6e-6): the bench runs
    cannot tell 3 from 6 angles (their washers' load is axisymmetric), this case can. The
    runs converge Newton to 1e-11: at the default 1e-8 the two runs' Newton paths part with
    the rules' round-off, and the stress then differs by up to 1.7e-8 between them (Newton's
    error, not the rule's; 5e-12 at 1e-11)."""
    from drivedyn.library.differentials.schema_sections import FlexibleWashers
    from drivedyn.solver import FixedStep, Newton, simulate
    from drivedyn.validation.fe import washer_bench

    figures = []
    for rule in (tuple(FlexibleWashers().face_quadrature), (2, 36)):
        sp, _ = washer_bench(2000.0, 0.1, 10.0, 1e9, quadrature=rule, tilt=3e-5)
        res = simulate(compile_model(sp), 0.03, step=FixedStep(1e-4), output_dt=1e-3,
                       newton=Newton(tol=1e-11))
        assert res.success, res.message
        figures.append([float(res.values(k)[-1]) for k in ("contact.friction_torque",
                                                             "washer.max_von_mises")])
    np.testing.assert_allclose(figures[0], figures[1], rtol=1e-9)
