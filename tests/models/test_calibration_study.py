"""What a calibration can claim (drivedyn.analysis.calibration_study) and the physical
ranges of the fitted numbers (drivedyn.analysis.calibrate): identities on synthetic
measurements, the mirror twins of the Type B, identifiability, and the bound rule."""

from __future__ import annotations

import math

import numpy as np
import pytest

from drivedyn.analysis import calibrate as C  # noqa: N812
from drivedyn.analysis import calibration_study as S  # noqa: N812
from drivedyn.config import read_library_file
from drivedyn.config.loader import ModelFileError
from drivedyn.library import differentials

TIED_B = [("washers.mu", "pockets.mu")]
BOX = [(0.03, 0.2)]


def _model_tdrs(p, values: dict[str, float]) -> dict[int, float]:
    q = C.with_values(p, values)
    return {m: float(differentials.of(q).analytic_bench(q, m)) for m in (1, 2, 3, 4)}


def test_synthetic_measurements_are_recovered() -> None:
    """Targets made by the model itself at mu = 0.1: the fit returns 0.1 (1e-7), every
    leave-out prediction is exact (1e-5 %), the profile's minimum and the spread hold 0.1.
    Fails when a tied group sets only its first key (the pockets keep the file's 0.1086 and
    the fit leaves 0.1), or when the spread moves the targets in one direction only (0.1
    then sits on an end of the spread)."""
    p, _, _ = read_library_file("torsen-b")
    targets = _model_tdrs(p, {"washers.mu": 0.1, "pockets.mu": 0.1})
    cal = C.calibrate(p, TIED_B, targets, confirm=False)
    assert cal.values["washers.mu"] == pytest.approx(0.1, abs=1e-7)
    distinct = S.distinct_measurements(p, cal.groups, targets, cal.bounds, 0.03)
    for left in S.cross_validate(p, cal.groups, targets, cal.bounds, distinct):
        assert left.identifiable
        for m in left.modes:
            assert abs(left.error_pct[m]) < 1e-5, (left.modes, left.error_pct)
    prof = S.profile(p, cal.groups, targets, cal.bounds, 0.03)["washers.mu, pockets.mu"]
    lo, hi = prof["interval"]
    assert lo < 0.1 < hi and prof["minimum"] == pytest.approx(0.1, abs=1e-6)
    assert min(prof["delta_chi2"]) >= 0.0
    spread = S.spread(p, cal.groups, targets, cal.bounds, 0.03)
    a, b = spread["values"]["washers.mu, pockets.mu"]
    assert a < 0.1 < b and spread["fits"] == 16 and spread["at_bound"] == 0
    for m, (a, b) in spread["tdr"].items():
        assert a < targets[m] < b


def test_mirror_twins_are_one_measurement() -> None:
    """Type B: modes 1 and 3, 2 and 4 differ by 2e-4 relative in the model (the middle
    washer turns with the left side gear), far below the 3 % uncertainty: two distinct
    measurements. Type C: four. Fails with TELL_APART = 0 (Type B: four singles) or a
    tolerance above the Type C's closest pair (modes 3 and 4, 9 % apart)."""
    p, _, _ = read_library_file("torsen-b")
    t = {1: 1.6, 2: 1.7, 3: 1.6, 4: 1.7}
    assert S.distinct_measurements(p, TIED_B, t, BOX, 0.03) == [(1, 3), (2, 4)]
    pc, _, _ = read_library_file("torsen-c")
    groups = [tuple(pc.calibration.fitted)]
    tc = {1: 4.02, 2: 2.82, 3: 1.57, 4: 1.62}
    assert S.distinct_measurements(pc, groups, tc, BOX, 0.03) == [(1,), (2,), (3,), (4,)]


def test_too_few_distinct_measurements_predict_nothing() -> None:
    """Type B with two numbers (washers, pockets) and two distinct measurements: leaving
    one out leaves one measurement for two numbers, which cannot determine them; the
    prediction is NaN and marked, not a number from wherever the optimiser stopped."""
    p, _, _ = read_library_file("torsen-b")
    groups = [("washers.mu",), ("pockets.mu",)]
    t = {1: 1.6, 2: 1.7, 3: 1.6, 4: 1.7}
    distinct = S.distinct_measurements(p, groups, t, BOX * 2, 0.03)
    out = S.cross_validate(p, groups, t, BOX * 2, distinct)
    assert [lo.modes for lo in out] == [(1, 3), (2, 4)]
    assert all(not lo.identifiable and all(math.isnan(v) for v in lo.predicted.values())
               for lo in out)


def test_profile_holds_the_shipped_fit() -> None:
    """The shipped value lies in its profile interval, and the profile's minimum is the
    shipped value (1e-5: the file rounds to 6 digits; the fit minimises the same sum).
    Fails if the profile weighs the modes differently from the fit (an absolute
    uncertainty: the Type C's interval then excluded its own fit, 0.191-0.192 vs 0.182) or
    takes the interval's ends from the coarse grid (the Type C's steep profile: its ends by
    linear interpolation left the fit outside, 0.1738-0.17647 vs 0.176526)."""
    for name in ("torsen-b", "torsen-c"):
        p, _, _ = read_library_file(name)
        groups = [tuple(p.calibration.fitted)]
        t = {int(k[-1]): v for k, v in p.calibration.targets.items()}
        box = C.group_bounds(p, groups)
        v = C.get_value(p, groups[0][0])
        prof = S.profile(p, groups, t, box, p.calibration.uncertainty)[", ".join(groups[0])]
        lo, hi = prof["interval"]
        assert lo < v < hi, (name, v, lo, hi)
        assert prof["minimum"] == pytest.approx(v, abs=1e-5)


def test_bounds_from_the_file() -> None:
    """A tied group takes the intersection of its keys' ranges; a key without a range is
    refused by name; the 1 % margin of the bound rule: 0.9 % from the bound is on it, 1.1 %
    is not (fails with an absolute margin such as the former 1e-6)."""
    p, _, _ = read_library_file("torsen-b", ['calibration.bounds={"washers.mu" = [0.03, 0.2], '
                                             '"pockets.mu" = [0.05, 0.15]}'])
    assert C.group_bounds(p, TIED_B) == [(0.05, 0.15)]
    with pytest.raises(KeyError, match=r"gears\.tooth_friction"):
        C.group_bounds(p, [("gears.tooth_friction",)])
    assert C.group_bounds(p, TIED_B, (0.02, 0.3)) == [(0.02, 0.3)]
    rng = 0.2 - 0.03
    assert C.bound_hits(TIED_B, np.array([0.2 - 0.009 * rng]), BOX)
    assert not C.bound_hits(TIED_B, np.array([0.2 - 0.011 * rng]), BOX)
    assert C.bound_hits(TIED_B, np.array([0.03 + 0.005 * rng]), BOX)


@pytest.mark.parametrize("value, needle", [
    ('{"washers.mu" = [0.2, 0.03]}', "0 <= low < high <= 1"),
    ('{"washers.mu" = [0.03]}', "0 <= low < high <= 1"),
    ('{"washers.r_int" = [0.03, 0.2]}', "friction coefficients"),
])
def test_bad_bounds_are_refused_by_key(value: str, needle: str) -> None:
    with pytest.raises(ModelFileError, match=r"calibration\.bounds") as exc:
        read_library_file("torsen-b", [f"calibration.bounds={value}"])
    assert needle in str(exc.value)
