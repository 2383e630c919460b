"""Solver behaviour: exact linear solutions, statics, initial conditions, step control,
failures as values with partial results, and results files."""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.solver.linear import DenseLU
from drivedyn.solver.simulate import consistent_initial_state

M, K = 2.0, 200.0  # oscillator mass [kg] and stiffness [N/m]: omega = 10 rad/s


def oscillator(c: float = 0.0, x0: float = 0.1, gravity: float = 0.0) -> dd.Spec:
    """A block on a prismatic joint along global z, on a spring to the ground.
    The spring's free length is 1 m; the block starts ``x0`` above it."""
    spec = dd.Spec(gravity=(0.0, 0.0, -gravity))
    spec.add_rigid_body("block", M, [0.1, 0.1, 0.1], position=(0.0, 0.0, 1.0 + x0))
    spec.add_marker("rail", "ground", position=(0.0, 0.0, 1.0 + x0), axis=(0, 0, 1))
    spec.add_marker("slider", "block", axis=(0, 0, 1))
    spec.add_marker("anchor", "ground")
    spec.add(dd.Prismatic("p", "rail", "slider"))
    spec.add(dd.SpringDamper("s", "anchor", "slider", stiffness=K, damping=c, free_length=1.0))
    return spec


def test_undamped_oscillator_against_exact_solution_and_energy():
    """x(t) = x0 cos(omega t). The trapezoidal member of the family (rho_inf = 1) has a phase
    error omega^3 h^2 t / 12 = 8e-5 rad here, so 3e-4 relative is its honest bound; for a
    linear undamped system it conserves energy exactly, so the balance is at round-off."""
    model = dd.compile_model(oscillator())
    res = dd.simulate(model, 1.0, step=dd.FixedStep(1e-3), integrator=dd.GeneralizedAlpha(1.0),
                      newton=dd.Newton(tol=1e-12, phi_tol=1e-14))
    assert res.success
    t = res.time
    z = res["block.position"].values[:, 2] - 1.0
    exact = 0.1 * np.cos(10.0 * t)
    assert np.abs(z - exact).max() < 3e-4 * 0.1
    e0 = 0.5 * K * 0.1**2
    assert abs(res["energy.balance_error"].values).max() < 1e-9 * e0
    np.testing.assert_allclose(res["energy.kinetic"] + res["energy.potential"], e0, rtol=1e-9)


def test_damped_oscillator_dissipation_is_accounted():
    """Energy lost by the block equals the energy the damper reports dissipated (balance
    below 1e-3 of the energy exchanged, the issue's criterion)."""
    model = dd.compile_model(oscillator(c=4.0))
    res = dd.simulate(model, 2.0, step=dd.FixedStep(1e-3), integrator=dd.GeneralizedAlpha(1.0))
    diss = res["s.dissipated_energy"].values[-1]
    assert diss > 0.5 * 0.5 * K * 0.1**2  # most of the energy is gone after 2 s
    assert abs(res["energy.balance_error"].values[-1]) < 1e-3 * diss
    np.testing.assert_allclose(res["energy.dissipated"].values[-1], diss)


def test_static_equilibrium_of_a_hanging_block():
    """Statics: the spring stretches by m g / k and the spring force carries the weight."""
    g = 9.81
    model = dd.compile_model(oscillator(gravity=g, x0=0.0))
    st = dd.solve_static(model)
    assert st.x[0, 2] - 1.0 == pytest.approx(-M * g / K, rel=1e-10)
    out = dd.element_outputs(model, st)
    assert out["s"]["force"] == pytest.approx(-M * g, rel=1e-9)  # compression carries m g
    assert abs(out["p"]["force_z"]) < 1e-9 * M * g  # the rail carries nothing vertically


def test_consistent_initial_acceleration_of_a_released_pendulum():
    """A rod released horizontally: angular acceleration m g d / I_o exactly, and an
    initial velocity that violates the hinge is projected away."""
    g, d, m = 9.81, 0.5, 3.0
    J = np.diag([0.01, 0.2, 0.2])
    spec = dd.Spec(gravity=(0.0, 0.0, -g))
    spec.add_rigid_body("rod", m, J, com=(d, 0.0, 0.0), velocity=(0.0, 0.3, 0.0))
    spec.add_marker("pivot", "ground", axis=(0, 1, 0))
    spec.add_marker("end", "rod", axis=(0, 1, 0))
    spec.add(dd.Hinge("h", "pivot", "end"))
    model = dd.compile_model(spec)
    st = consistent_initial_state(model, model.initial_state())
    np.testing.assert_allclose(st.v, 0.0, atol=1e-12)
    I_o = J[1, 1] + m * d * d
    # body y axis = global y; positive rotation about y moves +x down: alpha_y = +m g d / I_o
    assert st.vd[4] == pytest.approx(m * g * d / I_o, rel=1e-10)
    assert st.vd[2] == pytest.approx(-d * m * g * d / I_o, rel=1e-10)


def test_modified_and_full_newton_agree():
    model = dd.compile_model(oscillator(c=1.0))
    kw = {"step": dd.FixedStep(1e-3), "output_dt": 0.1}
    a = dd.simulate(model, 0.5, newton=dd.Newton("modified", tol=1e-11), **kw)
    b = dd.simulate(model, 0.5, newton=dd.Newton("full", tol=1e-11), **kw)
    np.testing.assert_allclose(a["block.position"], b["block.position"], atol=1e-12)
    assert a.stats.factorizations < b.stats.factorizations


def test_adaptive_step_meets_its_tolerance_with_fewer_steps():
    model = dd.compile_model(oscillator())
    res = dd.simulate(model, 1.0, step=dd.AdaptiveStep(h0=1e-4, h_max=0.02, rtol=1e-4,
                                                       atol=1e-9), output_dt=0.05)
    assert res.success, res.message
    z = res["block.position"].values[:, 2] - 1.0
    exact = 0.1 * np.cos(10.0 * res.time)
    # local relative error 1e-4 per step over ~100 steps with rho = 0.8 damping: 1e-2 is the
    # global bound we expect, and the run must be far cheaper than 1000 fixed steps
    assert np.abs(z - exact).max() < 1e-2 * 0.1
    assert res.stats.steps < 1000


def test_failure_is_a_value_with_partial_results():
    """A speed demand that jumps faster than h_min can resolve: the run stops near the jump
    with the time, the worst equation and its size, and keeps what was computed."""
    from small_models import speed_jump_spec

    model = dd.compile_model(speed_jump_spec())
    res = dd.simulate(model, 1.0, step=dd.AdaptiveStep(h0=1e-3, h_min=1e-4, h_max=1e-2),
                      output_dt=0.1)
    assert not res.success
    assert "simulation stopped at t = 0.5" in res.message
    assert "worst equation:" in res.message and "results up to t = 0.5" in res.message
    assert res.time[-1] == pytest.approx(0.5, abs=1e-3)
    assert len(res.time) >= 6  # outputs 0.0 .. 0.5 kept


def test_results_round_trip_netcdf_and_csv(tmp_path):
    model = dd.compile_model(oscillator(c=1.0))
    res = dd.simulate(model, 0.2, step=dd.FixedStep(1e-3), output_dt=0.05)
    path = res.to_netcdf(tmp_path / "out.nc")
    back = dd.load_results(path)
    assert back.success
    for name in ("block.position", "s.force", "energy.balance_error", "p.force_z"):
        np.testing.assert_array_equal(back[name].values, res[name].values)
        assert back[name].attrs["units"] == res[name].attrs["units"]
        assert back[name].attrs["description"]
    assert back.stats.steps == res.stats.steps
    csv = res.to_csv(tmp_path / "out.csv")
    header = csv.read_text().splitlines()[0]
    assert "time [s]" in header and "s.force [N]" in header


def test_netcdf_write_is_atomic(tmp_path, monkeypatch):
    model = dd.compile_model(oscillator())
    res = dd.simulate(model, 0.01, step=dd.FixedStep(1e-3))
    target = tmp_path / "r.nc"

    def boom(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(type(res.dataset), "to_netcdf", boom)
    with pytest.raises(KeyboardInterrupt):
        res.to_netcdf(target)
    assert list(tmp_path.iterdir()) == []


# -- linear solvers ------------------------------------------------------------------------


def _saddle_csc(n: int, m: int, seed: int):
    """A random saddle-point matrix [[K, G^T], [G, 0]]: its CSC arrays (canonical, as the
    model's fixed pattern) and its dense copy."""
    import scipy.sparse as sps

    rng = np.random.default_rng(seed)
    K = rng.normal(size=(n, n))
    K = K @ K.T + n * np.eye(n)
    G = rng.normal(size=(m, n))
    A = np.block([[K, G.T], [G, np.zeros((m, m))]])
    csc = sps.csc_matrix(A)
    return csc.data.copy(), csc.indices.astype(np.int32), csc.indptr.astype(np.int32), A


@pytest.mark.parametrize("n, m", [(5, 2), (90, 23)])
def test_dense_and_sparse_lu_solve_the_assembled_pattern(n: int, m: int) -> None:
    """Both solvers, fed the CSC arrays, solve the saddle-point system to round-off
    (residual relative to |A| |x| + |b|) and leave the arrays as they were."""
    from drivedyn.solver.linear import DenseLU, SparseLU

    data, indices, indptr, A = _saddle_csc(n, m, 3)
    b = np.arange(1.0, n + m + 1.0)
    kept = (data.copy(), indices.copy(), indptr.copy())
    for lin in (DenseLU(), SparseLU()):
        lin.factor_csc(data, indices, indptr, n + m)
        x = lin.solve(b)
        scale = np.abs(A) @ np.abs(x) + np.abs(b)
        assert np.max(np.abs(A @ x - b) / scale) < 1e-13
        for arr, ref in zip((data, indices, indptr), kept, strict=True):
            assert np.array_equal(arr, ref)
    # refactorising another matrix of the same size reuses the work array
    lin = DenseLU()
    lin.factor_csc(data, indices, indptr, n + m)
    lin.factor_csc(2.0 * data, indices, indptr, n + m)
    assert np.allclose(A @ lin.solve(b), 0.5 * b, rtol=1e-10, atol=1e-10)


def test_linear_solvers_name_the_compiled_calls_they_make() -> None:
    """``compiled_calls`` (handed to the first-run precompile) names exactly the overloads
    that factor_csc and solve compile: each predicted signature is one the dispatcher holds
    after a factorisation and a solve (a wrong one would be compiled in the workers for
    nothing, and the right one after them)."""
    from drivedyn.solver.linear import AutoLU, DenseLU, SparseLU

    data, indices, indptr, _ = _saddle_csc(5, 2, 3)
    b = np.arange(1.0, 8.0)
    predicted = set()
    for lin in (DenseLU(), SparseLU()):
        calls = lin.compiled_calls(indices, indptr)
        assert calls
        lin.factor_csc(data, indices, indptr, 7)
        lin.solve(b)
        for disp, sig in calls:
            assert sig in disp.overloads, (disp.py_func.__name__, sig)
            predicted.add((disp, sig))
    auto = AutoLU().compiled_calls(indices, indptr)
    assert set(auto) == predicted


def test_dense_lu_refuses_a_singular_matrix() -> None:
    from drivedyn.solver.linear import DenseLU

    data, indices, indptr, _ = _saddle_csc(4, 2, 5)
    cols = np.repeat(np.arange(6), np.diff(indptr))
    data = np.where(cols == 5, 0.0, data)    # a zero column: exactly singular
    with pytest.raises(np.linalg.LinAlgError):
        DenseLU().factor_csc(data, indices, indptr, 6)


def test_default_linear_solver_by_size() -> None:
    from drivedyn.solver.linear import DENSE_MAX, AutoLU, DenseLU, default_linear_solver

    assert isinstance(default_linear_solver(113), DenseLU)      # the TORSEN Type B bench
    assert isinstance(default_linear_solver(DENSE_MAX + 1), AutoLU)


def test_auto_lu_keeps_sparse_for_a_banded_matrix_and_goes_dense_when_it_fills() -> None:
    """A tridiagonal matrix stays with SuperLU; a matrix with a random 5 % pattern (no order
    keeps its factors sparse, like the saddle-point matrix of the 4WD vehicle) fills and goes
    dense; both solve exactly."""
    import scipy.sparse as sps

    from drivedyn.solver.linear import AutoLU, DenseLU, SparseLU

    n = 200
    rng = np.random.default_rng(3)
    band = sps.diags([np.full(n - 1, -1.0), np.full(n, 4.0), np.full(n - 1, -1.0)],
                     [-1, 0, 1]).tocsc()
    scattered = (sps.random(n, n, density=0.05, random_state=4)
                 + sps.diags(np.full(n, 10.0))).tocsc()
    for A, kind in ((band, SparseLU), (scattered, DenseLU)):
        lin = AutoLU()
        lin.factor(A)
        assert isinstance(lin.active, kind)
        b = rng.standard_normal(n)
        assert np.allclose(A @ lin.solve(b), b, rtol=1e-12, atol=1e-12)


def test_auto_lu_decides_at_its_first_factorisation_only(monkeypatch) -> None:
    """On one pattern, a later matrix whose pivots leave the diagonal fills more than the
    first (here 25 % of the matrix against 17 %, with DENSE_FILL set between them): the
    sparse LU is kept, and it solves exactly. The solver of a run does not follow the
    pivots the run meets. Fails with the fill tested at every factorisation (the second
    goes dense)."""
    import scipy.sparse as sps

    from drivedyn.solver import linear

    monkeypatch.setattr(linear, "DENSE_FILL", 0.2)
    n = 200
    A1 = (sps.random(n, n, density=0.02, random_state=4) + sps.diags(np.full(n, 100.0))).tocsc()
    A1.sort_indices()
    A2 = A1.copy()
    A2.setdiag(1e-6)   # the same pattern, pivots off the diagonal
    A2 = A2.tocsc()
    A2.sort_indices()
    assert np.array_equal(A1.indices, A2.indices)
    lin = linear.AutoLU()
    lin.factor(A1)
    assert isinstance(lin.active, linear.SparseLU) and lin.active.fill < 0.2 * n * n
    lin.factor(A2)
    assert isinstance(lin.active, linear.SparseLU) and lin.active.fill > 0.2 * n * n
    b = np.random.default_rng(5).standard_normal(n)
    x = lin.solve(b)   # backward stable (A2 is ill-conditioned: the solve's residual)
    d = A2.toarray()
    assert np.abs(d @ x - b).max() < 1e-12 * (np.abs(d).max() * np.abs(x).max())


class _StalledSolver(DenseLU):
    """A dense LU whose corrections are zero (in the Python oracle, which solves through
    ``solve``): Newton stalls with the residual where the predictor left it (the situation
    an acceptance at the positions' round-off alone would let through)."""

    def solve(self, b):
        return np.zeros_like(b)


def test_newton_accepts_a_step_only_when_the_residual_criterion_holds():
    """A zero correction is 'at round-off' of the positions, but the residual of the
    predictor is far above the tolerance: the step must not be accepted. Checked on the
    oracle (reference_stepper.py), which the engine matches bit for bit
    (test_step_loop.py); accepting on the correction's size alone makes it fail."""
    from reference_stepper import ReferenceStepper

    from drivedyn.solver.settings import StepStatus

    model = dd.compile_model(oscillator(c=1.0))
    st = model.initial_state()
    stepper = ReferenceStepper(model, dd.GeneralizedAlpha(0.8), dd.Newton(), _StalledSolver())
    consistent_initial_state(model, st, stepper.sys, DenseLU())
    out = stepper.step(st, 1e-3)
    assert out.status is StepStatus.NEWTON_MAX_ITER


def test_accepted_steps_meet_the_residual_criterion_at_a_dead_centre(monkeypatch):
    """A slider-crank started from rest at a dead centre: the residual of the stiff
    constraint forces stalls at the round-off of the positions (|A| eps |x|). Each accepted
    step's residual, evaluated afresh, is within the tolerance beyond that level, computed
    here independently from the dense iteration matrix (the floor of each equation's scale
    is FLOOR_REL of the largest force sum carried so far). Run by the oracle, one
    ReferenceStepper.step per step (the engine takes the same steps: test_step_loop.py)."""
    from reference_stepper import ReferenceStepper, reference_runs

    from drivedyn.elements.framework.contract import MODE_DYN
    from drivedyn.solver.newton_kernel import FLOOR_REL, ROUNDOFF_ULPS
    from drivedyn.timefunctions import SmoothStep
    from drivedyn.validation.engine import slider_crank_model

    model = slider_crank_model(0.0, ("speed", SmoothStep(0.0, 0.5, 0.0, 4.0 * np.pi)),
                               guide_spring=(2000.0, 5.0))
    nd = model.nd
    newton = dd.Newton()
    checked = []
    original = ReferenceStepper.step

    def step(self, sn, h):
        carried = self.force_scale  # the largest force sum of the steps before this one
        out = original(self, sn, h)
        if out.ok and self.lu_h is not None:
            tr = self.trial
            self.sys.evaluate(tr, 1.0 / (self.bp * h * h), self.gp / (self.bp * h), 1.0,
                              MODE_DYN, True)
            A = np.abs(self.sys.matrix().toarray())
            eps = np.finfo(float).eps * ROUNDOFF_ULPS
            e = np.concatenate([np.full(nd, eps * max(1.0, np.abs(tr.x).max())),
                                eps * np.abs(tr.lam)])
            r, ra = self.sys.r, self.sys.rabs
            floor = FLOOR_REL * max(ra[:nd].max(), carried)
            # the matrix at the converged state, not at the factorisation: 2 x the level
            beyond = np.maximum(np.abs(r) - 2.0 * (A @ e), 0.0)
            checked.append(max((beyond[:nd] / (ra[:nd] + floor)).max() / newton.tol,
                               (beyond[nd:] / self.sys.kscale[nd:]).max() / newton.phi_tol))
        return out

    monkeypatch.setattr(ReferenceStepper, "step", step)
    with reference_runs(monkeypatch):
        res = dd.simulate(model, 0.05, step=dd.FixedStep(1e-3), newton=newton,
                          integrator=dd.GeneralizedAlpha(0.9))
    assert res.success, res.message
    assert checked and max(checked) <= 1.0


@pytest.mark.parametrize("name", ["torsen-c", "flexible-driveshaft", "vehicle-4wd"])
def test_bound_kernel_calls_equal_the_dispatcher_bit_for_bit(name: str) -> None:
    """`System.evaluate` calls each group's compiled overload directly once it has been
    identified: residual, scales, matrix and element outputs must be those of
    the numba dispatcher, bit for bit, in every mode, also for a new State object."""
    from drivedyn.config.loader import load_model, resolve_path
    from drivedyn.elements.framework.contract import MODE_ACC, MODE_DYN, MODE_VEL
    from drivedyn.solver.system import System

    model = load_model(resolve_path(name))
    st = model.initial_state()
    st.v[:] = np.random.default_rng(0).normal(size=st.v.shape) * 0.1
    fast, slow = System(model), System(model)
    for mode, want in ((MODE_DYN, False), (MODE_DYN, True), (MODE_ACC, True),
                       (MODE_VEL, True)):
        slow._calls[(mode, want)] = False  # the dispatcher every time
        for trial in (st, st.copy()):
            for _ in range(2):  # the first call binds, the second takes the bound path
                fast.evaluate(trial, 2.0, 3.0, 1.0, mode, want)
            assert fast._calls[(mode, want)], "no overload was bound"
            out_fast = [fast.r.copy(), fast.rabs.copy(), fast.data.copy()]
            aux_fast = [g.aux.copy() for g in model.groups]
            slow.evaluate(trial, 2.0, 3.0, 1.0, mode, want)
            for a, b in zip(out_fast, (slow.r, slow.rabs, slow.data), strict=True):
                assert np.array_equal(a, b)
            for a, g in zip(aux_fast, model.groups, strict=True):
                assert np.array_equal(a, g.aux)


def test_residual_floor_is_the_largest_force_sum_carried() -> None:
    """Node residuals are scaled by their own force sum plus FLOOR_REL times the largest
    force sum, of the state or carried before (``amin``): an unloaded state (a differential
    at zero torque after a loaded level) is solved to the same absolute accuracy as the
    loaded one, not to 1e-12 of its own round-off-sized forces."""
    from drivedyn.solver.newton_kernel import FLOOR_REL, residual_norms

    r = np.array([1e-9, -2e-6, 0.0, 3e-12])  # two node equations, two constraint rows
    rabs = np.array([1e-3, 4.0, 0.0, 0.0])
    kscale = np.ones(4)
    roff = np.zeros(4)
    rq, ph, ok = residual_norms(r, rabs, kscale, 2, FLOOR_REL, roff)
    assert ok and ph == 3e-12
    assert rq == pytest.approx(max(1e-9 / (1e-3 + 4.0 * FLOOR_REL), 2e-6 / (4.0 + 4.0 * FLOOR_REL)),
                               rel=1e-15)
    rq, _, _ = residual_norms(r, rabs, kscale, 2, FLOOR_REL, roff, 1e4)
    fl = FLOOR_REL * 1e4
    assert rq == pytest.approx(max(1e-9 / (1e-3 + fl), 2e-6 / (4.0 + fl)), rel=1e-15)


def test_sparse_lu_refactorisation_is_the_fresh_factorisation() -> None:
    """SparseLU factorises the first matrix with pivot search (gp_factor) and later ones
    with its pivots (gp_refactor): for new values whose pivots stay the same, the factors
    are bit for bit those of a fresh factorisation; when a kept pivot becomes too small
    (here a diagonal entry scaled by 1e-6), it factorises afresh and still solves to
    round-off."""
    import scipy.sparse as sps

    from drivedyn.solver.linear import SparseLU
    from drivedyn.solver.sparse_lu import gp_refactor

    data, indices, indptr, A = _saddle_csc(60, 17, 4)
    n = A.shape[0]
    b = np.linspace(-1.0, 2.0, n)
    lin = SparseLU()
    lin.factor_csc(data, indices, indptr, n)
    data2 = data * (1.0 + 0.01 * np.sin(np.arange(data.size)))  # same pivots, new values
    # the refactorisation is accepted (0) for these values
    assert gp_refactor(n, indptr, indices, data2, lin._q, lin.diag_pivot_thresh, lin._Lp,
                       lin._Lio, lin._Lx, lin._Up, lin._Ux, lin._pinv, lin._prow, lin._Rp,
                       lin._Ri, lin._x, lin._tail) == 0
    lin._compact()
    fresh = SparseLU()
    fresh.factor_csc(data2, indices, indptr, n)
    # the used part of each array (the solves read the columns' ranges; a refactorisation
    # compacts in place, so entries past them may be those of an earlier factorisation)
    lz, uz = lin._f[0][-1], lin._f[3][-1]
    used = (None, lz, lz, None, uz, uz, None, None)
    for a, f, k in zip(lin._f[:-1], fresh._f[:-1], used, strict=True):
        assert np.array_equal(a[:k], f[:k])
    assert lin.tail == 0  # (the tail's refactorisation: test_sparse_lu_dense_tail_...)
    # shrink the first pivot: the kept pivot order is refused, a new one is searched
    col = lin._q[0]  # the column of the first elimination step
    rows = indices[indptr[col]:indptr[col + 1]]
    d = data2.copy()
    d[indptr[col] + int(np.flatnonzero(rows == lin._prow[0])[0])] *= 1e-6
    lin.factor_csc(d, indices, indptr, n)
    A3 = sps.csc_matrix((d, indices, indptr), shape=(n, n)).toarray()
    x = lin.solve(b)
    assert np.max(np.abs(A3 @ x - b) / (np.abs(A3) @ np.abs(x) + np.abs(b))) < 1e-13
    assert lin._prow[0] != fresh._prow[0]



@pytest.mark.parametrize("share, afresh", [(3e-3, False), (3e-4, True)])
def test_sparse_lu_keeps_a_pivot_down_to_its_refactorisation_threshold(
        share: float, afresh: bool) -> None:
    """A refactorisation keeps the last pivots while each is at least
    ``REFACTOR_THRESHOLD`` (1e-3) of its column's largest candidate, a tenth of the pivot
    search's 0.01: with the first pivot shrunk to 3e-3 of its column's largest entry the
    matrix is refactorised with it (no new pivot search) and still solves to round-off; at
    3e-4 it is factorised afresh. Fails with the refactorisation held to the search's
    threshold (the first case searches afresh), or with no test of the kept pivots (the
    second does not). Bad thresholds are refused by name."""
    import scipy.sparse as sps

    from drivedyn.solver.linear import REFACTOR_THRESHOLD, SparseLU

    assert 3e-4 < REFACTOR_THRESHOLD < 3e-3
    data, indices, indptr, A = _saddle_csc(60, 17, 4)
    n = A.shape[0]
    lin = SparseLU()
    lin.factor_csc(data, indices, indptr, n)
    assert lin.fresh == 1
    # the first elimination step's column: its pivot entry set to ``share`` of the largest
    # other entry (at the first step the candidates are the column's entries themselves)
    col = lin._q[0]
    lo, hi = indptr[col], indptr[col + 1]
    rows = indices[lo:hi]
    k = lo + int(np.flatnonzero(rows == lin._prow[0])[0])
    d = data * (1.0 + 0.01 * np.sin(np.arange(data.size)))
    others = np.delete(np.abs(d[lo:hi]), k - lo)
    d[k] = np.copysign(share * others.max(), d[k])
    lin.factor_csc(d, indices, indptr, n)
    assert lin.fresh == (2 if afresh else 1)
    A2 = sps.csc_matrix((d, indices, indptr), shape=(n, n)).toarray()
    b = np.linspace(-1.0, 2.0, n)
    x = lin.solve(b)
    assert np.max(np.abs(A2 @ x - b) / (np.abs(A2) @ np.abs(x) + np.abs(b))) < 1e-12
    with pytest.raises(ValueError, match=r"refactor_thresh = 0\.1"):
        SparseLU(refactor_thresh=0.1)
    with pytest.raises(ValueError, match="diag_pivot_thresh = 2"):
        SparseLU(diag_pivot_thresh=2)


def _hub_csc(nblocks: int = 4, nb: int = 30, nh: int = 6, seed: int = 1):
    """A matrix of ``nblocks`` sparse symmetric blocks of ``nb`` unknowns, each coupled
    through three of its unknowns to a hub of ``nh`` (the pattern of a vehicle: sub-systems
    on one body): CSC arrays and the dense copy."""
    import scipy.sparse as sps

    rng = np.random.default_rng(seed)
    n = nblocks * nb + nh
    A = np.zeros((n, n))
    for k in range(nblocks):
        s = slice(k * nb, (k + 1) * nb)
        B = rng.normal(size=(nb, nb)) * (rng.random((nb, nb)) < 0.15)
        A[s, s] = B + B.T + 2 * nb * np.eye(nb)
        for r in rng.choice(nb, 3, replace=False) + k * nb:
            h = nblocks * nb + rng.integers(nh)
            A[r, h] = A[h, r] = rng.normal()
    A[-nh:, -nh:] += 10.0 * np.eye(nh)
    c = sps.csc_matrix(A)
    return c.data.copy(), c.indices.astype(np.int64), c.indptr.astype(np.int64), A


def test_sparse_lu_keeps_the_order_with_the_fewest_refactorisation_operations(
        monkeypatch) -> None:
    """SparseLU("auto") factorises the first matrix in each order of ORDERS and keeps the
    one whose refactorisation takes the fewest multiply-adds (on this hub matrix the
    minimum degree of A^T + A, put between the other two here), then solves to round-off.
    refactor_ops is checked against the count per row of U: row J's off-diagonal entries
    each apply column J of L below its diagonal. Fails if "auto" keeps the first order
    tried or the last one instead of the best, or if refactor_ops counts the diagonals."""
    import scipy.sparse as sps

    from drivedyn.solver import linear
    from drivedyn.solver.linear import SparseLU

    data, indices, indptr, A = _hub_csc()
    n = A.shape[0]
    ops = {}
    for spec in linear.ORDERS:
        lin = SparseLU(spec)
        lin.factor_csc(data, indices, indptr, n)
        ops[spec] = lin.refactor_ops
        U = sps.csc_matrix((np.ones(lin._unz), lin._Ui[:lin._unz], lin._Up), shape=(n, n))
        per_row = np.asarray(U.tocsr().sum(axis=1)).ravel() - 1.0  # off-diagonal, row J
        below = np.diff(lin._Lp) - 1.0
        assert ops[spec] == int(below @ per_row) > 0
    assert ops["MMD_AT_PLUS_A"] < min(ops["COLAMD"], ops["MMD_ATA"])
    monkeypatch.setattr(linear, "ORDERS", ("COLAMD", "MMD_AT_PLUS_A", "MMD_ATA"))
    auto = SparseLU()
    auto.factor_csc(data, indices, indptr, n)
    assert auto.order == "MMD_AT_PLUS_A" and auto.refactor_ops == ops["MMD_AT_PLUS_A"]
    b = np.linspace(1.0, 2.0, n)
    x = auto.solve(b)
    assert np.max(np.abs(A @ x - b) / (np.abs(A) @ np.abs(x) + np.abs(b))) < 1e-13
    with pytest.raises(ValueError, match="permc_spec = 'METIS'"):
        SparseLU("METIS")



def _chain_saddle_csc(nb: int = 40, seed: int = 2):
    """The iteration matrix of a chain of ``nb`` bodies of 3 coordinates (SPD blocks,
    springs between neighbours) and a joint of 2 constraint rows between each pair of
    neighbours (zero multiplier block): CSC arrays and the dense copy."""
    import scipy.sparse as sps

    rng = np.random.default_rng(seed)
    nd, nm = 3 * nb, 2 * (nb - 1)
    A = np.zeros((nd + nm, nd + nm))
    for i in range(nb):
        B = rng.normal(size=(3, 3))
        A[3 * i:3 * i + 3, 3 * i:3 * i + 3] = B @ B.T + 3.0 * np.eye(3)
        if i:
            A[3 * i, 3 * i - 3] = A[3 * i - 3, 3 * i] = -0.5
    for j in range(nb - 1):
        G = rng.normal(size=(2, 6))
        cols = np.r_[3 * j:3 * j + 6]
        A[nd + 2 * j:nd + 2 * j + 2, cols] = G
        A[np.ix_(cols, np.r_[nd + 2 * j:nd + 2 * j + 2])] = G.T
    c = sps.csc_matrix(A)
    return c.data.copy(), c.indices.astype(np.int64), c.indptr.astype(np.int64), A


def test_saddle_point_order_takes_every_pivot_on_the_diagonal() -> None:
    """The SADDLE order (the minimum degree of A^T + A with each zero-diagonal column moved
    after the last of its neighbours) on a chain of jointed bodies: a permutation in which
    every multiplier comes after all of its coordinates; the factorisation then takes every
    pivot on the diagonal (the minimum degree alone reaches multipliers first: row
    interchanges) and solves to round-off; whether it is the cheaper order depends on the
    matrix (here it is not), which ``SparseLU("auto")`` settles by counting. Fails if the
    multipliers are not moved (pivots off the diagonal) or moved
    after the first of their coordinates instead of the last."""
    import scipy.sparse as sps

    from drivedyn.solver.linear import SADDLE, SparseLU, saddle_point_order

    data, indices, indptr, A = _chain_saddle_csc()
    n = A.shape[0]
    nd = 3 * 40  # the chain's 40 bodies of 3 coordinates
    plain = SparseLU("MMD_AT_PLUS_A")
    plain.factor_csc(data, indices, indptr, n)
    assert np.any(plain._prow != plain._q)  # the plain order interchanges rows
    q = saddle_point_order(plain._q, sps.csc_matrix(A))
    assert np.array_equal(np.sort(q), np.arange(n))
    pos = np.empty(n, np.int64)
    pos[q] = np.arange(n)
    for m in range(nd, n):
        coords = np.flatnonzero(A[:nd, m])
        assert pos[m] > pos[coords].max()
    lin = SparseLU(SADDLE)
    lin.factor_csc(data, indices, indptr, n)
    assert np.array_equal(lin._q, q)
    assert np.array_equal(lin._prow, lin._q)  # every pivot on the diagonal
    b = np.linspace(1.0, 2.0, n)
    x = lin.solve(b)
    assert np.max(np.abs(A @ x - b) / (np.abs(A) @ np.abs(x) + np.abs(b))) < 1e-13


@pytest.mark.parametrize("spec, choices", [("auto", 2), ("COLAMD", 1)])
def test_sparse_lu_chooses_its_order_again_once_when_the_first_pivots_fail(
        monkeypatch, spec: str, choices: int) -> None:
    """SparseLU("auto") chooses its column order on the first matrix and once more at the
    first refactorisation whose kept pivots are refused (the first matrix, a model at rest,
    need not stand for the run), never again after; a fixed order is never chosen again.
    Fails if the order is chosen at every refused refactorisation, at none, or for a fixed
    order."""
    import scipy.sparse as sps

    from drivedyn.solver.linear import SparseLU

    data, indices, indptr, A = _saddle_csc(60, 17, 4)
    n = A.shape[0]
    calls = []
    lin = SparseLU(spec)
    order = lin._order
    monkeypatch.setattr(lin, "_order", lambda *a: (calls.append(1), order(*a)))

    def refused(d: np.ndarray) -> np.ndarray:
        """``d`` with the first pivot's entry shrunk: the kept pivots are refused."""
        col = lin._q[0]
        rows = indices[indptr[col]:indptr[col + 1]]
        d = d.copy()
        d[indptr[col] + int(np.flatnonzero(rows == lin._prow[0])[0])] *= 1e-9
        return d

    lin.factor_csc(data, indices, indptr, n)
    lin.factor_csc(data * 1.01, indices, indptr, n)  # same pivots: refactorised
    assert len(calls) == 1
    for _ in range(3):
        d = refused(data)
        lin.factor_csc(d, indices, indptr, n)
        x = lin.solve(np.ones(n))
        A3 = sps.csc_matrix((d, indices, indptr), shape=(n, n)).toarray()
        assert np.max(np.abs(A3 @ x - 1.0) / (np.abs(A3) @ np.abs(x) + 1.0)) < 1e-13
    assert len(calls) == choices


def _gear_row(n: int) -> dd.Spec:
    """``n`` spur gears on hinges in a row, meshing (no backlash), 100 N m on the first, a
    damper on the last: the row of ``benchmarks/gear_chain.py``, linear once the flanks
    are loaded."""
    spec = dd.Spec(gravity=(0.0, 0.0, 0.0))
    axis = (0.0, 0.0, 1.0)
    for i in range(n):
        pos = (0.1 * i, 0.0, 0.0)
        spec.add_rigid_body(f"gear{i}", 1.0, (1e-3, 1e-3, 1e-3), position=pos)
        spec.add_marker(f"g{i}", dd.GROUND, position=pos, axis=axis)
        spec.add_marker(f"m{i}", f"gear{i}", axis=axis)
        spec.add(dd.Hinge(f"hinge{i}", f"g{i}", f"m{i}"))
        if i > 0:
            spec.add(dd.GearPair(f"mesh{i}", f"m{i - 1}", f"m{i}", 50, 50, 2e-3, 0.02,
                                 stiffness=1e8, damping=1e3))
    spec.add(dd.Torque("drive", "m0", vector=(0.0, 0.0, 100.0)))
    spec.add_marker("g_damper", dd.GROUND, position=(0.1 * (n - 1), 0.0, 0.0), axis=axis)
    spec.add(dd.TorsionalSpringDamper("ground_damper", "g_damper", f"m{n - 1}",
                                      stiffness=0.0, damping=1.0))
    return spec


def test_a_matrix_costing_every_step_an_iteration_is_refreshed() -> None:
    """A factorisation that costs every step a second Newton iteration is refreshed once
    those extra iterations reach a factorisation's price (``newton_kernel.EXCESS_MAX``),
    although each step contracts well (the refresh by contraction alone never fires).

    The row of gears starts at rest with its flanks unloaded: the first matrix, taken there,
    makes every later step take two iterations; refreshed once the load is on, one. Fails
    on the error it names: without the count (``EXCESS_MAX`` = 10**9, seen with the tests'
    oracle) the run takes 1.66 iterations per step on one factorisation, against 1.01."""
    res = dd.simulate(dd.compile_model(_gear_row(10)), 0.1,
                      integrator=dd.GeneralizedAlpha(rho_inf=0.9), step=dd.FixedStep(1e-4),
                      output_dt=0.01)
    st = res.stats
    assert res.success and st.steps == 1000
    assert st.newton_iterations / st.steps < 1.1, (st.newton_iterations, st.factorizations)


def test_lu_paths_from_python_take_the_dense_path_for_no_sparse_factors() -> None:
    """``lu_factor`` and ``lu_solve`` (solver.lu_paths) called from Python with
    ``sparse=None`` factorise and solve with the dense LU whatever the flags say (as the
    loop compiled for ``sparse=None`` does): the solution of a random well-conditioned
    system against numpy's to 1e-12, a singular matrix reported as FACTOR_SINGULAR. Fails if
    the Python dispatch takes the branch for sparse factors on None (seen: it unpacks None)
    or drops the dense factorisation's outcome."""
    import scipy.sparse as sp

    from drivedyn.solver.lapack import workspace
    from drivedyn.solver.lu_paths import FACTOR_SINGULAR, FACTORED, lu_factor, lu_solve

    rng = np.random.default_rng(3)
    n = 7
    A = rng.standard_normal((n, n)) + n * np.eye(n)
    b = rng.standard_normal(n)
    csc = sp.csc_matrix(A)
    linear = workspace(n)
    assert lu_factor(csc.data, csc.indices, csc.indptr, linear, None, True, True) == FACTORED
    x = b.copy()
    lu_solve(linear, None, False, x)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=0, atol=1e-12)
    A[:, 2] = 0.0  # a zero column: exactly singular
    csc = sp.csc_matrix(A)
    assert lu_factor(csc.data, csc.indices, csc.indptr, linear, None, True,
                     True) == FACTOR_SINGULAR


def _chain_and_hub(nc: int = 300, nh: int = 60, seed: int = 3) -> np.ndarray:
    """A banded chain of ``nc`` unknowns (bandwidth 3), every fifth one coupled to six of a
    dense hub of ``nh``: the factors' fill gathers in the hub's last columns, as in a
    vehicle's (sub-systems on one frame)."""
    rng = np.random.default_rng(seed)
    n = nc + nh
    A = np.zeros((n, n))
    for i in range(nc):
        lo, hi = max(0, i - 3), min(nc, i + 4)
        A[i, lo:hi] = rng.normal(size=hi - lo)
        A[i, i] += 10.0
    A[nc:, nc:] = rng.normal(size=(nh, nh)) + nh * np.eye(nh)
    for r in range(0, nc, 5):
        for h in rng.choice(nh, 6, replace=False):
            A[r, nc + h] = rng.normal()
            A[nc + h, r] = rng.normal()
    return A


def test_sparse_lu_dense_tail_solves_and_refactorises_as_afresh(monkeypatch) -> None:
    """The last columns of a matrix whose fill gathers there are factorised as one dense
    block by LAPACK (sparse_lu's tail): the chain-and-hub matrix takes a tail (of at most
    half the columns), solves to round-off, and agrees with the factors without a tail; a
    refactorisation with new values gives the factors of a fresh factorisation bit for bit
    (the tail's block included); the sparse loop's operations fall by the tail's share and
    ``fill`` counts the block. Fails with the Schur complement left without the sparse
    columns' update (``_tail_factor`` skipping the L columns: the residual is of order 1),
    with the tail's rows of U left out of the back substitution, or with a refactorisation
    that refactorises the tail from stale values."""
    import scipy.sparse as sps

    import drivedyn.solver.linear as linear
    from drivedyn.solver.linear import SparseLU

    A = _chain_and_hub()
    n = A.shape[0]
    c = sps.csc_matrix(A)
    data, indices, indptr = c.data.copy(), c.indices.astype(np.int64), c.indptr.astype(np.int64)
    b = np.linspace(-1.0, 2.0, n)

    def solved(lin, d):
        x = lin.solve(b)
        M = sps.csc_matrix((d, indices, indptr), shape=(n, n)).toarray()
        return x, np.max(np.abs(M @ x - b) / (np.abs(M) @ np.abs(x) + np.abs(b)))

    lin = SparseLU()
    lin.factor_csc(data, indices, indptr, n)
    assert 32 <= lin.tail <= n // 2
    x, res = solved(lin, data)
    assert res < 1e-14
    with monkeypatch.context() as mp:
        mp.setattr(linear, "tail_size", lambda Lp, Up, Ui: 0)
        plain = SparseLU()
        plain.factor_csc(data, indices, indptr, n)
    assert plain.tail == 0 and plain.order == lin.order
    x0, _ = solved(plain, data)
    assert np.max(np.abs(x - x0)) < 1e-12 * np.max(np.abs(x0))
    assert lin.refactor_ops < 0.8 * plain.refactor_ops
    assert lin.fill == lin._lnz + lin._unz + lin.tail ** 2
    # new values on the same pattern: refactorised with the kept pivots, as afresh
    data2 = data * (1.0 + 0.01 * np.sin(np.arange(data.size)))
    lin.factor_csc(data2, indices, indptr, n)
    assert lin.fresh == 1
    _, res2 = solved(lin, data2)
    assert res2 < 1e-14
    fresh = SparseLU()
    fresh.factor_csc(data2, indices, indptr, n)
    assert fresh.tail == lin.tail
    lz, uz = lin._f[0][-1], lin._f[3][-1]
    used = (None, lz, lz, None, uz, uz, None, None)
    for a, f, k in zip(lin._f[:-1], fresh._f[:-1], used, strict=True):
        assert np.array_equal(a[:k], f[:k])
    for k in (0, 1, 4):  # the block's factors, LAPACK's pivots, n0 (not the scratch)
        assert np.array_equal(lin._tail[k], fresh._tail[k])
