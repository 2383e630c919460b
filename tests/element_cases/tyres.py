"""Tangent cases of the tyre element: Magic Formula with and without relaxation, the simple
formula, a road patch edge under the wheel."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.tyre import RoadPatch, TyreContact
from drivedyn.model.spec import Spec
from drivedyn.tyres import read_tir, shipped, simple_tyre


def _wheel(tyre, **kw) -> Spec:
    spec = Spec()
    spec.add_rigid_body("wheel", 20.0, np.diag([0.6, 1.0, 0.6]), position=(0.2, 0.1, 0.33),
                        velocity=(8.0, 0.3, 0.0), angular_velocity=(0.0, 26.0, 0.0))
    # marker z along the wheel's +y (spin axis to the tyre's left)
    spec.add_marker("hub", "wheel", position=(0.0, 0.01, 0.0), axis=(0.0, 1.0, 0.0))
    spec.add(TyreContact("tyre", "hub", tyre, **kw))
    return spec


def mf_case() -> Spec:
    return _wheel(read_tir(shipped("pac2002_235_60R16")), mu=0.8)


def mf_steady_case() -> Spec:
    return _wheel(read_tir(shipped("pac2002_235_60R16")), relaxation=False)


def simple_case() -> Spec:
    return _wheel(simple_tyre("wet", unloaded_radius=0.344))


def patch_case() -> Spec:
    return _wheel(read_tir(shipped("pac2002_235_60R16")),
                  patches=(RoadPatch(0.15, 5.0, 0.3),), transition=0.2)


CASES = (mf_case, mf_steady_case, simple_case, patch_case)
