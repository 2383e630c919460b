"""Small models, and the rotation matrices that place their parts, shared by several test
modules."""

from __future__ import annotations

import numpy as np

import drivedyn as dd


def speed_jump_spec() -> dd.Spec:
    """A disk on a hinge whose prescribed speed jumps from 0 to 1000 rad/s within 1 ns at
    t = 0.5 s: faster than any step down to a practical h_min can resolve (a run that must
    fail there and keep its results)."""
    spec = dd.Spec()
    spec.add_rigid_body("disk", 1.0, [0.01, 0.01, 0.02])
    spec.add_marker("g", "ground", axis=(0, 0, 1))
    spec.add_marker("m", "disk", axis=(0, 0, 1))
    spec.add(dd.Hinge("h", "g", "m"))
    jump = dd.Table([0.0, 0.5, 0.5 + 1e-9, 1.0], [0.0, 0.0, 1e3, 1e3])
    spec.add(dd.JointDriver("d", "h", jump, quantity="speed"))
    return spec


def rot_y(a: float) -> np.ndarray:
    """Rotation by ``a`` [rad] about the y axis."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    """Rotation by ``a`` [rad] about the z axis."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def tet_box(L: float, a: float, n: int, nyz: int = 2):
    """A box ``L x a x a`` [m] of tetrahedra (``SolidMesh``, kind ``"tet"``): ``n x nyz x nyz``
    hexahedra, each split into six (Kuhn), every tetrahedron oriented positively."""
    from drivedyn.fe import box
    from drivedyn.fe.mesh import SolidMesh

    m = box(L, a, a, n, nyz, nyz)
    kuhn = ((0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6), (0, 5, 1, 6))
    cells = np.concatenate([m.cells[:, list(k)] for k in kuhn])
    p = m.points[cells]
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
    cells[vol < 0] = cells[vol < 0][:, [0, 2, 1, 3]]
    return SolidMesh(m.points, cells, "tet", "tet box")
