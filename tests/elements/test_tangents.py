"""Every element family's tangent matrices against finite differences.

The loop runs over the element registry, so a family added later is checked without
touching this file; its cases live in ``element_cases.TANGENT_CASES`` (test fixtures), and a
registered family without an entry there fails the test. Node rotations are
perturbed through the Lie-group update ``R <- R exp(eps e_i)``, exactly the right
perturbation the kernels differentiate for; translations, velocities, accelerations and
multipliers are perturbed additively. Central differences with eps = 1e-6 have a truncation
error ~1e-12 relative; 1e-6 relative tolerance leaves room for round-off of ~1e-16/1e-6 per
unit of residual magnitude.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_stepper import ReferenceStepper

from drivedyn.elements import REGISTRY
from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, MODE_VEL
from drivedyn.model.compile import compile_model
from drivedyn.rotations import exp_so3
from drivedyn.solver.settings import GeneralizedAlpha, Newton
from drivedyn.solver.system import System
from element_cases import TANGENT_CASES
from element_cases.basic import joint_case
from fdcheck import EPS, assembled, check, perturb, residual


def _cases():
    out = []
    for name in sorted(REGISTRY):
        cases = TANGENT_CASES.get(name, [])
        if not cases:
            out.append(pytest.param(name, None, id=f"{name}-missing"))
        for i, c in enumerate(cases):
            out.append(pytest.param(name, c, id=f"{name}-{i}"))
    return out


def _perturbed_state(model, rng):
    st = model.initial_state()
    nn = model.nn
    st.x[:nn] += 1e-2 * rng.standard_normal((nn, 3))
    for i in range(nn):
        st.R[i] = st.R[i] @ exp_so3(0.05 * rng.standard_normal(3))
    st.v[:] = rng.standard_normal(model.nd)
    st.vd[:] = rng.standard_normal(model.nd)
    # multipliers such that the constraint forces k lam are O(1..10) whatever k is
    st.lam[:] = 5.0 * rng.standard_normal(model.nm) / model.meta["kscale"][model.nd :]
    st.t = 0.37
    return st


def test_every_family_has_tangent_cases():
    missing = [n for n in REGISTRY if not TANGENT_CASES.get(n)]
    assert not missing, f"element families without tangent cases: {missing}"
    stale = sorted(set(TANGENT_CASES) - set(REGISTRY))
    assert not stale, f"tangent cases of unregistered families: {stale}"


@pytest.mark.parametrize(("family", "case"), _cases())
def test_tangents_against_finite_differences(family, case):
    assert case is not None, f"family {family!r} has no tangent case"
    spec = case()
    model = compile_model(spec)
    assert any(g.family == family for g in model.groups)
    rng = np.random.default_rng(7)
    st = _perturbed_state(model, rng)
    sys = System(model)
    nd, neq = model.nd, model.neq

    # K (and G, G^T): derivative of the full residual w.r.t. positions and multipliers
    rmax = np.abs(residual(sys, st)).max()
    K = assembled(sys, st, 0.0, 0.0, 1.0)
    F = np.zeros((neq, neq))
    for j in range(neq):
        F[:, j] = (residual(sys, perturb(st, j, EPS, nd)) -
                   residual(sys, perturb(st, j, -EPS, nd))) / (2 * EPS)
    check(K, F, f"{family}: stiffness/constraint tangent", rmax)

    # C: derivative w.r.t. velocities (node rows and columns)
    C = assembled(sys, st, 0.0, 1.0, 0.0)[:nd, :nd]
    F = np.zeros((nd, nd))
    for j in range(nd):
        sp, sm = st.copy(), st.copy()
        sp.v[j] += EPS
        sm.v[j] -= EPS
        F[:, j] = (residual(sys, sp) - residual(sys, sm))[:nd] / (2 * EPS)
    check(C, F, f"{family}: damping tangent", rmax)

    # M: derivative w.r.t. accelerations
    M = assembled(sys, st, 1.0, 0.0, 0.0)[:nd, :nd]
    F = np.zeros((nd, nd))
    for j in range(nd):
        sp, sm = st.copy(), st.copy()
        sp.vd[j] += EPS
        sm.vd[j] -= EPS
        F[:, j] = (residual(sys, sp) - residual(sys, sm))[:nd] / (2 * EPS)
    check(M, F, f"{family}: mass matrix", rmax)

    # acceleration- and velocity-level constraint rows are linear in vd and v with the
    # same gradient G, and their convective term equals d^2 Phi / dt^2 along the motion
    if model.nm:
        A = assembled(sys, st, 1.0, 0.0, 0.0, MODE_ACC)
        G = A[nd:, :nd]
        sp, sm = st.copy(), st.copy()
        d = rng.standard_normal(nd)
        sp.vd += EPS * d
        sm.vd -= EPS * d
        dr = (residual(sys, sp, MODE_ACC) - residual(sys, sm, MODE_ACC))[nd:] / (2 * EPS)
        np.testing.assert_allclose(dr, G @ d, rtol=1e-6, atol=1e-6 * np.abs(G @ d).max())
        sp, sm = st.copy(), st.copy()
        sp.v += EPS * d
        sm.v -= EPS * d
        dr = (residual(sys, sp, MODE_VEL) - residual(sys, sm, MODE_VEL))[nd:] / (2 * EPS)
        np.testing.assert_allclose(dr, G @ d, rtol=1e-6, atol=1e-6 * np.abs(G @ d).max())


@pytest.mark.parametrize(("family", "case"), [c for c in _cases() if c.values[1] is not None])
def test_second_time_derivative_of_constraints(family, case):
    """MODE_ACC rows give k (g.vd + v^T H v + Phi_tt) = k d^2 Phi/dt^2: checked by
    integrating the motion q(t) = q0 o exp(t v + t^2/2 vd) and differentiating twice."""
    model = compile_model(case())
    if model.nm == 0:
        pytest.skip("no constraint rows")
    rng = np.random.default_rng(3)
    st0 = _perturbed_state(model, rng)
    sys = System(model)
    nd, nn = model.nd, model.nn

    def phi_at(tau):
        s = st0.copy()
        s.t = st0.t + tau
        for i in range(nn):
            inc = tau * st0.v[6 * i : 6 * i + 6] + 0.5 * tau**2 * st0.vd[6 * i : 6 * i + 6]
            s.x[i] = st0.x[i] + inc[:3]
            s.R[i] = st0.R[i] @ exp_so3(inc[3:])
        # states (accumulated angles) follow the motion continuously for small tau
        return residual(sys, s)[nd:]

    h = 1e-4
    d2 = (phi_at(h) - 2 * phi_at(0.0) + phi_at(-h)) / h**2
    acc = residual(sys, st0, MODE_ACC)[nd:]
    np.testing.assert_allclose(acc, d2, rtol=1e-5, atol=1e-5 * max(1.0, np.abs(d2).max()))


def test_newton_matrix_of_a_step_against_finite_differences():
    """The whole iteration matrix of a generalized-alpha step (mass, damping, stiffness with
    the tangent operator T(h dq), constraint blocks) against finite differences of the step
    residual with respect to the Newton unknowns (Lie-algebra increment and multipliers)."""
    from drivedyn.elements.joints import Hinge

    spec = joint_case(Hinge)
    spec.add_marker("mA3", "A", position=(0.1, 0.0, 0.0))
    spec.add_marker("gnd", "ground", position=(0.5, 0.5, 0.5))
    from drivedyn.elements.springs import SpringDamper

    spec.add(SpringDamper("s", "gnd", "mA3", stiffness=200.0, damping=5.0))
    model = compile_model(spec)
    rng = np.random.default_rng(11)
    sn = _perturbed_state(model, rng)
    sn.a[:] = rng.standard_normal(model.nd)
    stepper = ReferenceStepper(model, GeneralizedAlpha(0.7), Newton(max_iter=0))
    h = 0.05  # a large step so that T(h dq) is far from identity
    stepper.step(sn, h)
    hdq0 = stepper.hdq.copy()
    st = stepper.trial.copy()
    bp, gp = stepper.bp, stepper.gp
    cM, cC = 1.0 / (bp * h * h), gp / (bp * h)
    sys = stepper.sys
    from drivedyn.solver.system import lie_update

    def res(delta):
        s = st.copy()
        dx = delta[: model.nd]
        s.vd += cM * dx
        s.v += cC * dx
        s.lam += delta[model.nd :]
        lie_update(sn.x, sn.R, hdq0 + dx, model.nn, s.x, s.R, sys.Tn, False)
        sys.evaluate(s, cM, cC, 1.0, MODE_DYN, False)
        return sys.r.copy()

    lie_update(sn.x, sn.R, hdq0, model.nn, st.x, st.R, sys.Tn, True)
    sys.evaluate(st, cM, cC, 1.0, MODE_DYN, True)
    A = sys.matrix().toarray()
    F = np.zeros_like(A)
    for j in range(model.neq):
        e = np.zeros(model.neq)
        e[j] = EPS
        F[:, j] = (res(e) - res(-e)) / (2 * EPS)
    check(A, F, "generalized-alpha iteration matrix")
