"""Closed loops with redundant constraint rows (every revolute a hinge) run, and move as the
same mechanisms built without redundant rows (drivedyn.solver.redundancy)."""

from __future__ import annotations

import logging

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.solver import redundancy
from drivedyn.solver.settings import FixedStep, GeneralizedAlpha
from drivedyn.solver.statics import solve_static
from drivedyn.solver.system import System
from drivedyn.validation.closed_loops import (
    FB_LINKS,
    bricard_model,
    four_bar_model,
    hinge_violations,
)

# a double wishbone seen from the front: lower arm 0.3 m, upright 0.25 m, upper arm 0.22 m,
# chassis pivots 0.2 m apart; suspension spring 2 kN/m, 20 N s/m
DW_LINKS = (0.3, 0.25, 0.22, 0.2)
DW_SPRING = (2000.0, 20.0)


def _run(model, t_end=1.0, h=1e-3, **kw):
    res = dd.simulate(model, t_end, step=FixedStep(h), **kw)
    assert res.success, res.message
    return res


def test_four_bar_of_hinges_moves_as_the_non_redundant_build(caplog):
    """A planar four-bar of four hinges (3 redundant rows) driven at 1 rev/s moves as the
    same four-bar built with a spherical and a universal joint (no redundant rows): coupler
    positions within 1e-12 m, the driving torque (a unique reaction) within 1e-8 of its
    range (Newton's residual tolerance: the two builds converge each step differently,
    measured 2e-9). The rows set aside are logged and kept in the results.

    Fails if the dependent rows are not set aside (the run stops at start: singular matrix),
    or if an independent row is set aside (``RANK_TOL = 0.5``: the motion leaves the
    loop, see test_setting_aside_an_independent_row_is_seen)."""
    with caplog.at_level(logging.WARNING, logger="drivedyn"):
        hinges = _run(four_bar_model("hinges"))
    mixed = _run(four_bar_model("mixed"))
    assert "3 redundant constraint row(s) set aside" in caplog.text
    attrs = hinges.dataset.attrs
    assert attrs["redundant_constraints"].count("hinge") == 3
    assert "not unique" in attrs["redundant_constraints_note"]
    assert "redundant_constraints" not in mixed.dataset.attrs
    dx = np.abs(hinges["coupler.position"].values - mixed["coupler.position"].values).max()
    assert dx < 1e-12
    tq_h, tq_m = hinges["drive.torque"].values, mixed["drive.torque"].values
    assert np.abs(tq_h - tq_m).max() < 1e-8 * np.ptp(tq_m)
    assert hinge_violations(hinges, four_bar_model("hinges")).max() < 1e-12


def test_setting_aside_an_independent_row_is_seen(monkeypatch):
    """The checks above can fail: with a rank tolerance of 0.5 independent rows are set
    aside too, and the loop comes apart (a hinge violated by more than 1e-6)."""
    monkeypatch.setattr(redundancy, "RANK_TOL", 0.5)
    monkeypatch.setattr(redundancy.dependent_rows, "__defaults__", (0.5,))
    model = four_bar_model("hinges")
    res = dd.simulate(model, 0.3, step=FixedStep(1e-3))
    assert (not res.success) or hinge_violations(res, model).max() > 1e-6


def test_dependent_rows_by_groups_are_those_of_one_factorisation():
    """``dependent_rows`` factorises each group of rows that share no dof alone; the rows it
    finds must be those of one pivoted QR of the whole scaled Jacobian (written here as
    the reference): as many, the rows kept independent and spanning all candidates. Random
    Jacobians of 12 groups (single rows among them), each group with 0-3 rows that are
    combinations of two of its others, rows shuffled. Fails with each group's rows set
    aside in their stored order instead of the pivots' order, or with the pivot order
    reversed (seen)."""
    from scipy.linalg import qr

    def one_factorisation(G, candidates, length, tol=redundancy.RANK_TOL):
        idx = np.flatnonzero(candidates)
        A = G[idx].copy()
        A[:, (np.arange(A.shape[1]) % 6) >= 3] /= length
        A /= np.sqrt((A * A).sum(axis=1))[:, None]
        _q, Rf, piv = qr(A.T, mode="economic", pivoting=True)
        d = np.abs(np.diag(Rf))
        return np.sort(idx[piv[int((d > tol * d[0]).sum()):]])

    rng = np.random.default_rng(3)
    for _ in range(20):
        blocks, nd = [], 0
        for _g in range(12):
            ncol = int(rng.integers(1, 9))
            nind = int(rng.integers(1, ncol + 1))
            base = rng.standard_normal((nind, ncol)) * 10.0 ** rng.uniform(-3, 3, (nind, 1))
            ndep = int(rng.integers(0, 4)) if nind > 1 else 0
            # combinations of two of the rows: the others are in no dependency and must
            # be kept
            dep = rng.standard_normal((ndep, 2)) @ base[:2] if ndep else base[:0]
            blocks.append((nd, np.vstack([base, dep])))
            nd += ncol
        nd += (-nd) % 6
        G = np.zeros((sum(b.shape[0] for _, b in blocks), nd))
        r = 0
        for c0, b in blocks:
            G[r:r + b.shape[0], c0:c0 + b.shape[1]] = b
            r += b.shape[0]
        G = G[rng.permutation(G.shape[0])]
        cand = rng.random(G.shape[0]) < 0.9
        found = redundancy.dependent_rows(G, cand, 0.7)
        # which rows of a dependent set are set aside is a tie between rows of equal
        # (normalised) size, broken by round-off in either factorisation: the number is
        # compared, and the rows kept must be independent and span all candidates
        assert found.size == one_factorisation(G, cand, 0.7).size
        kept = np.setdiff1d(np.flatnonzero(cand), found)
        A = G / np.sqrt((G * G).sum(axis=1))[:, None]
        assert np.linalg.matrix_rank(A[kept]) == kept.size
        assert np.linalg.matrix_rank(A[cand]) == kept.size


@pytest.mark.parametrize("scale", [0.01, 100.0])
def test_redundant_rows_found_at_any_scale(scale):
    """The same three rows of a four-bar of hinges are found dependent when the mechanism
    is 1 cm or 35 m long (rotation columns scaled by the model's length, rows normalised).
    Fails without the scaling (``length`` = 1 m: at 35 m the lever arms dominate and
    round-off decides) or with an absolute instead of a relative rank tolerance."""
    base = System(four_bar_model("hinges", speed=None)).dependent_constraints(
        four_bar_model("hinges", speed=None).initial_state())
    m = four_bar_model("hinges", speed=None, links=tuple(scale * x for x in FB_LINKS))
    rows = System(m).dependent_constraints(m.initial_state())
    assert rows.size == base.size == 3


def test_double_wishbone_of_hinges():
    """A double wishbone in the front view (lower and upper arm on chassis hinges, upright
    on two hinges: 3 redundant rows) settling on its spring under gravity from 0.15 rad of
    lower-arm angle: the upright's position and rotation as the non-redundant build's
    (within 1e-12), the spring force (a unique reaction) within 1e-9 N, and its static
    equilibrium the same. Fails if the dependent rows are not set aside (singular at start,
    in the run and in the statics) or an independent one is (the loop comes apart)."""
    kw = dict(theta0=0.15, speed=None, plane="yz", spring=DW_SPRING, links=DW_LINKS)
    mh, mm = four_bar_model("hinges", **kw), four_bar_model("mixed", **kw)
    rh, rm = _run(mh), _run(mm)
    for q in ("coupler.position", "coupler.rotation"):
        assert np.abs(rh[q].values - rm[q].values).max() < 1e-12
    assert np.abs(rh["spring.force"].values - rm["spring.force"].values).max() < 1e-9
    assert rh.dataset.attrs["redundant_constraints"].count("hinge") == 3
    sh, sm = solve_static(mh), solve_static(mm)
    ih, im = mh.node_index["coupler"], mm.node_index["coupler"]
    assert np.abs(sh.x[ih] - sm.x[im]).max() < 1e-10
    assert abs(sh.x[ih, 2] - mh.state0.x[ih, 2]) > 1e-3  # it did settle


def test_bricard_linkage_moves_with_one_degree_of_freedom():
    """Bricard's orthogonal linkage (six hinges, 30 rows for 30 coordinates, mobile): one
    row is set aside, the linkage moves (a link travels more than 1 m), every hinge row
    holds within 1e-12, and the energy error is second order: it falls 12-20 times from
    h = 1 ms to 0.25 ms (16 for order 2). Fails if the row set aside were independent
    (the hinges come apart) or with no row set aside (singular at start)."""
    m = bricard_model()
    errs = []
    for h in (1e-3, 2.5e-4):
        res = _run(m, 1.0, h, integrator=GeneralizedAlpha(0.95))
        assert res.dataset.attrs["redundant_constraints"].count("hinge") == 1
        assert hinge_violations(res, m).max() < 1e-12
        x = res["link2.position"].values
        assert np.linalg.norm(x - x[0], axis=1).max() > 1.0
        E = res["energy.kinetic"].values + res["energy.potential"].values
        errs.append(np.abs(E - E[0]).max())
    assert 12.0 < errs[0] / errs[1] < 20.0


def test_independent_row_set_aside_is_given_back(monkeypatch):
    """A row set aside that is not implied by the others (here forced at the start: one
    of the universal joint's rows of the non-redundant four-bar) is violated beyond
    RESTORE_FACTOR x phi_tol after the first step, the compiled loop returns, the rows are
    found again and it is given back: from the next step on the driven loop is where the
    normal run's is (positions within 1e-12 m; the first step, taken without the row,
    is 1.2e-4 m off) and the change is in the results. Fails if the watch is not checked
    after accepted steps (the loop comes apart: violation > 1e-6)."""
    model = four_bar_model("mixed")
    ref = _run(model, 0.3)
    row = model.eq_labels.index("universal rocker_pin: constraint 1")

    def forced(self, st):
        self.redundancy.set_rows(np.array([row]))
        self.redundancy.at_start = self.redundancy.rows.copy()
        return self.redundancy.rows

    monkeypatch.setattr(System, "detect_redundancy", forced)
    res = _run(model, 0.3)
    assert "restored universal rocker_pin: constraint 1" in \
        res.dataset.attrs["redundant_constraints_changes"]
    assert hinge_violations(res, model).max() < 1e-9
    dx = np.abs(res["coupler.position"].values - ref["coupler.position"].values)
    assert dx[1].max() > 1e-6  # the first step went off the loop
    assert dx[2:].max() < 1e-12


def test_singular_factorisation_sets_rows_aside_during_a_run(monkeypatch):
    """Rows that become dependent during a run (here: none were set aside at the start of
    a four-bar of hinges, as if the rank had dropped after it) make a factorisation
    singular; the loop returns, the dependent rows are set aside and the step is made
    again: the run finishes as the normal one. Fails if a singular factorisation is a
    rejection only (the run stops: singular iteration matrix)."""
    model = four_bar_model("hinges")
    ref = _run(model, 0.3)
    st = model.initial_state()
    dd.solver.consistent_initial_state(model, st)
    monkeypatch.setattr(System, "detect_redundancy", lambda self, st: self.redundancy.rows)
    res = _run(model, 0.3, state=st, initialize=False)
    assert "set aside" in res.dataset.attrs["redundant_constraints_changes"]
    dx = np.abs(res["coupler.position"].values - ref["coupler.position"].values).max()
    assert dx < 1e-9


def test_redundant_rows_reported_before_any_run():
    """``dd.redundant_constraints`` names, before any run, the rows a run sets aside: three
    hinge rows of the four-bar of hinges, none for the non-redundant build, the same rows
    the run then reports. Fails if it finds no rows or other rows than the run (seen with
    ``RANK_TOL = 0.5``: it then lists independent rows too)."""
    model = four_bar_model("hinges")
    before = dd.redundant_constraints(model)
    assert len(before) == 3 and all("hinge" in r for r in before), before
    assert dd.redundant_constraints(four_bar_model("mixed")) == []
    res = _run(model, t_end=0.05)
    assert res.dataset.attrs["redundant_constraints"] == "; ".join(before)


@pytest.mark.parametrize("build", ["mixed", "hinges"])
def test_initial_positions_projected_onto_the_constraints(build):
    """A four-bar started with its coupler 2e-7 m off the loop (as a static start from
    another model or a file's rounded positions leave it): the run's initial state is
    projected onto the constraints to Newton.phi_tol (1e-10) and an adaptive run at
    atol 1e-9 m takes its steps. Fails without the projection
    (``consistent_initial_state(..., phi_tol=None)`` in Simulation): the first step has to
    close the 2e-7 m, which the step control counts as error at any step size, and the run
    stops at t = 0 with h_min reached."""
    from drivedyn.elements.framework.contract import MODE_DYN
    from drivedyn.solver.initial_state import project_positions
    from drivedyn.solver.linear import default_linear_solver

    model = four_bar_model(build)
    st = model.initial_state()
    i = model.node_index["coupler"]
    st.x[i, 0] += 2e-7
    sys = System(model)
    sys.detect_redundancy(st)
    sys.evaluate(st, 0.0, 0.0, 1.0, MODE_DYN, False)
    assert sys.constraint_violation().max() > 1e-7
    left = project_positions(model, st.copy(), sys, default_linear_solver(model.neq), 1e-10)
    assert left <= 1e-10
    res = dd.simulate(model, 0.05, state=st, output_dt=1e-2,
                      step=dd.AdaptiveStep(1e-4, 1e-9, 1e-3, rtol=1e-6, atol=1e-9))
    assert res.success, res.message
