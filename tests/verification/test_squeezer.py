"""Andrews' squeezing mechanism (``drivedyn.validation.squeezer``): the independent
seven-angle reference against the IVP test set, and drivedyn's fixed-step runs converging to
it at second order.

Each test names the deliberate mutation that makes it fail.
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.validation import squeezer as S  # noqa: N812


def test_seven_angle_equations_give_the_test_sets_initial_accelerations():
    """The index-1 solve at the initial state reproduces the test set's consistent
    accelerations (14222.44, -10666.83 rad/s^2, the others zero) and multipliers (98.567,
    -6.1227, the others zero): the mass matrix, forces and constraint Jacobian agree with the
    literature's. Fails if, e.g., the spring's point D takes ``+ sc`` instead of the quarter
    turn (``(SC, 1, _GAMMA)``), or the motor torque is dropped."""
    qdd, lam = S.accelerations(S.Q0, np.zeros(7))
    assert qdd[:2] == pytest.approx(S.QDD0, rel=1e-12)
    assert np.abs(qdd[2:]).max() < 1e-9
    assert lam[:2] == pytest.approx(S.LAM0, rel=1e-12)
    assert np.abs(lam[2:]).max() < 1e-12
    _, _, g, _, _ = S.equations(S.Q0, np.zeros(7))
    assert np.abs(g).max() < 1e-15


def test_reference_agrees_with_the_test_sets_solution():
    """scipy's DOP853 on the index-1 form at rtol 1e-12 lands within 3e-9 rad of the test
    set's reference angles at t = 0.03 s (the crank has turned 2.5 times, beta = 15.8 rad).
    Fails if the reference integrates at rtol 1e-6 (errors of 1e-6 rad) or drops the
    velocity terms ``dG/dt qd``."""
    q, qd = S.reference_solution()
    assert np.abs(q - S.TESTSET_Q_END).max() < 3e-9
    _, _, g, G, _ = S.equations(q, qd)
    assert np.abs(g).max() < 1e-14
    assert np.abs(G @ qd).max() < 1e-9


def test_fixed_steps_converge_to_the_reference_at_second_order():
    """drivedyn's rigid-body model (non-redundant joint mix, 41 rows) with fixed steps of
    20, 10 and 5 us: the crank angle beta and the relative angle theta at t = 0.03 s converge
    to the reference with slopes 2 +- 0.2, and the 5 us error is below 3e-5 rad. Fails if
    the spring's free length is off by 1 % (the error stalls at 1e-2 rad), or if the
    universal joint at B takes its second axis along B-E (a free tilt: singular matrix)."""
    model = S.squeezer_model()
    qref, _ = S.reference_solution()
    hs = np.array([2e-5, 1e-5, 5e-6])
    errs = []
    for h in hs:
        res = dd.simulate(model, S.T_END, step=dd.FixedStep(h), output_dt=1e-4)
        assert res.success, res.message
        beta, theta = S.squeezer_angles(res)
        errs.append([abs(beta[-1] - qref[0]), abs(theta[-1] - qref[1])])
    errs = np.array(errs)
    slopes = np.log(errs[:-1] / errs[1:]) / np.log(hs[:-1, None] / hs[1:, None])
    assert np.all(np.abs(slopes - 2.0) < 0.2), (errs, slopes)
    assert errs[-1].max() < 3e-5, errs


def test_hinge_variant_moves_as_the_non_redundant_build():
    """``joints="hinges"`` builds the ten planar hinges: 50 constraint rows, 9 more than the
    non-redundant mix, and the solver sets exactly 9 dependent rows aside; the crank angle
    and theta follow the mixed build's within 1e-9 rad over the 0.03 s (measured 1.1e-10:
    each build meets Newton's tolerance in its own way), and so does the spring force (a
    unique reaction) within 1e-6 of its largest value. Fails if the variant silently builds
    the mixed joints (no rows set aside), or if a dependent row is kept (singular at start)
    or an independent one set aside (the loops come apart: errors of 1e-3 rad)."""
    mixed = S.squeezer_model()
    hinges = S.squeezer_model("hinges")
    assert len(hinges.eq_labels) - len(mixed.eq_labels) == 9
    assert len(mixed.eq_labels) == 42 + 41
    with pytest.raises(ValueError, match="joints"):
        S.squeezer_model("planar")
    rm, rh = (dd.simulate(m, S.T_END, step=dd.FixedStep(2e-6), output_dt=2e-4)
              for m in (mixed, hinges))
    assert rm.success and rh.success
    assert rh.dataset.attrs["redundant_constraints"].count("hinge") == 9
    for a, b in zip(S.squeezer_angles(rm), S.squeezer_angles(rh), strict=True):
        assert np.abs(a - b).max() < 1e-9
    fm, fh = rm["spring.force"].values, rh["spring.force"].values
    assert np.abs(fm - fh).max() < 1e-6 * np.abs(fm).max()


def test_second_order_down_to_small_steps_at_any_scale():
    """The squeezer (7 cm) and the same mechanism 100 times larger (dynamically similar: the
    same angles), with modified Newton at tol 1e-10: the crank angle's error at t = 0.03 s
    falls 4 times per halving of h (3.6-4.4) from 1.25 us down to 0.3125 us, to below 1e-7
    rad, and the two scales give the same errors within 2 %. Fails with a stagnation exit
    sized in metres (64 ulps of max(1 m, largest coordinate)): at the 7 cm scale Newton
    stopped early and the error stayed at 6.8e-7 rad at 0.3125 us, against 8.8e-8 at 7 m.

    At the default tolerance, :func:`test_second_order_with_the_default_newton`."""
    qref, _ = S.reference_solution()
    errs = []
    for scale in (1.0, 100.0):
        model = S.squeezer_model(scale=scale)
        for h in (1.25e-6, 6.25e-7, 3.125e-7):
            res = dd.simulate(model, S.T_END, step=dd.FixedStep(h),
                              newton=dd.Newton(tol=1e-10), output_dt=2e-4)
            assert res.success, res.message
            errs.append(abs(S.squeezer_angles(res)[0][-1] - qref[0]))
    errs = np.array(errs).reshape(2, 3)
    ratios = errs[:, :-1] / errs[:, 1:]
    assert np.all((ratios > 3.6) & (ratios < 4.4)), (errs, ratios)
    assert errs[:, -1].max() < 1e-7
    assert np.abs(errs[1] / errs[0] - 1.0).max() < 0.02, errs


def test_second_order_with_the_default_newton():
    """The same order test with the default Newton (modified, tol 1e-8), at both scales:
    errors 1.41e-6, 3.52e-7, 8.8e-8 rad (measured), 4 times smaller per halving of h
    (3.6-4.4). Fails without the closing correction of a converged step (newton_kernel):
    each step then keeps an error within the tolerance of one sign, the crank's error gets a
    bias of +1e-7 rad whatever h, and the errors were 1.31e-6, 2.50e-7, 5.5e-9 (ratio 45)."""
    qref, _ = S.reference_solution()
    errs = []
    for scale in (1.0, 100.0):
        model = S.squeezer_model(scale=scale)
        for h in (1.25e-6, 6.25e-7, 3.125e-7):
            res = dd.simulate(model, S.T_END, step=dd.FixedStep(h), output_dt=2e-4)
            assert res.success, res.message
            errs.append(abs(S.squeezer_angles(res)[0][-1] - qref[0]))
    errs = np.array(errs).reshape(2, 3)
    ratios = errs[:, :-1] / errs[:, 1:]
    assert np.all((ratios > 3.6) & (ratios < 4.4)), (errs, ratios)
    assert np.abs(errs[1] / errs[0] - 1.0).max() < 0.02, errs


def test_adaptive_steps_follow_the_tolerance():
    """Adaptive steps on the squeezer. With atol from 1e-7 to 1e-10 (rtol 1e-12) the crank
    angle's error at t = 0.03 s falls monotonically, 0.6-0.85 decade per decade of atol on a
    least-squares line through the four runs (2/3 for an error-per-step control of a
    second-order method; measured 0.66, the decades 0.57, 0.74, 0.66: an error at one instant
    holds some cancellation, so a single decade's slope is noise around the line), with at most
    5 % of the steps rejected; with atol 1e-9 and rtol 1e-4 and 1e-5 (the relative part of
    the weight dominating) at most 6 % rejected; and an adaptive run is more accurate than a
    fixed-step run of as many attempts. Fails with the error estimate on the one-step change
    of the pseudo-accelerations, whose alternating numerical mode it takes for error (7 %
    rejected at atol 1e-7, 17-18 % at rtol 1e-4)."""
    model = S.squeezer_model()
    qref, _ = S.reference_solution()

    def run(step):
        res = dd.simulate(model, S.T_END, step=step, output_dt=2e-4)
        assert res.success, res.message
        st = res.stats
        return abs(S.squeezer_angles(res)[0][-1] - qref[0]), st.steps, st.rejected

    errs = []
    for atol in (1e-7, 1e-8, 1e-9, 1e-10):
        err, steps, rejected = run(dd.AdaptiveStep(h0=1e-6, h_min=1e-12, h_max=1e-3,
                                                   rtol=1e-12, atol=atol))
        assert rejected <= 0.05 * (steps + rejected), (atol, steps, rejected)
        errs.append(err)
        attempts = steps + rejected
    assert np.all(np.diff(errs) < 0), errs
    slope = np.polyfit(np.log10([1e-7, 1e-8, 1e-9, 1e-10]), np.log10(errs), 1)[0]
    assert 0.6 < slope < 0.85, (errs, slope)
    fixed, _, _ = run(dd.FixedStep(S.T_END / attempts))
    assert errs[-1] < fixed, (errs[-1], fixed)
    for rtol in (1e-4, 1e-5):
        _, steps, rejected = run(dd.AdaptiveStep(h0=1e-6, h_min=1e-12, h_max=1e-3, rtol=rtol,
                                                 atol=1e-9))
        assert rejected <= 0.06 * (steps + rejected), (rtol, steps, rejected)
