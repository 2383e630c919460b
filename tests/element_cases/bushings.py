"""Tangent cases of the bushing: linear axes, tabulated curves with preload, Maxwell branches,
markers apart with differently oriented frames, one side on the ground."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.bushing import (
    Bushing,
    BushingCurve,
    BushingRotationalCurve,
    MaxwellBranch,
    RotationalMaxwellBranch,
)
from drivedyn.model.spec import Spec
from drivedyn.rotations import exp_so3
from element_cases.basic import _RA, _RB, _two_bodies

_LINEAR = dict(stiffness=(2.0e3, 3.0e3, 1.5e3), damping=(20.0, 15.0, 30.0),
               rotational_stiffness=(300.0, 200.0, 400.0), rotational_damping=(3.0, 2.0, 1.0),
               preload=(5.0, -3.0, 8.0), rotational_preload=(1.0, 0.5, -2.0))


def _curves() -> dict:
    """Tables on z and rx spanning about the deflections of the perturbed states (1e-2 m,
    0.05 rad), so that both the cubic pieces and the linear extensions are evaluated."""
    return dict(
        curves=(BushingCurve("z", (-0.02, -0.005, 0.0, 0.004, 0.012),
                             (-90.0, -12.0, 10.0, 25.0, 80.0)),),
        rotational_curves=(BushingRotationalCurve("x", (-0.06, 0.0, 0.03, 0.05),
                                                  (-30.0, 2.0, 8.0, 25.0)),))


def _branches() -> dict:
    return dict(
        branches=(MaxwellBranch("x", 1.0e3, 80.0), MaxwellBranch("x", 500.0, 400.0),
                  MaxwellBranch("z", 800.0, 150.0)),
        rotational_branches=(RotationalMaxwellBranch("y", 100.0, 20.0),
                             RotationalMaxwellBranch("z", 50.0, 30.0)))


def linear_case() -> Spec:
    spec = Spec()
    a, b = _two_bodies(spec)
    spec.add(Bushing("bu", a, b, **_LINEAR))
    return spec


def curve_case() -> Spec:
    spec = Spec()
    a, b = _two_bodies(spec)
    lin = dict(_LINEAR, stiffness=(2.0e3, 3.0e3, 0.0), rotational_stiffness=(0.0, 200.0, 400.0))
    spec.add(Bushing("bu", a, b, **lin, **_curves()))
    return spec


def branch_case() -> Spec:
    """Two bushings in one group, one without branches (its state slots stay unused)."""
    spec = Spec()
    a, b = _two_bodies(spec)
    spec.add(Bushing("bu", a, b, **_LINEAR, **_branches()))
    lin = dict(_LINEAR, stiffness=(2.0e3, 3.0e3, 0.0), rotational_stiffness=(0.0, 200.0, 400.0))
    spec.add(Bushing("bu2", a, b, **lin, **_curves()))
    return spec


def offset_case() -> Spec:
    """Markers 0.15 m apart with unrelated frames (d0 and B's frame correction active),
    everything on."""
    spec = Spec()
    _two_bodies(spec)
    spec.add_marker("mA2", "A", position=(0.1, -0.05, 0.2), rotation=exp_so3(np.array(
        [0.4, 0.1, -0.6])))
    spec.add_marker("mB2", "B", position=_RB.T @ (np.array([0.35, -0.1, 0.55])
                                                  - np.array([-0.2, 0.4, 0.3])),
                    rotation=_RA)
    lin = dict(_LINEAR, stiffness=(2.0e3, 3.0e3, 0.0), rotational_stiffness=(0.0, 200.0, 400.0))
    spec.add(Bushing("bu", "mA2", "mB2", **lin, **_curves(), **_branches()))
    return spec


def ground_case() -> Spec:
    spec = Spec()
    a, b = _two_bodies(spec, ground_a=True)
    spec.add(Bushing("bu", a, b, **_LINEAR, **_branches()))
    return spec


CASES = (linear_case, curve_case, branch_case, offset_case, ground_case)
