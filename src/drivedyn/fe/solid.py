"""Linear elastic solid: stiffness, consistent mass and stress recovery with scikit-fem.

Quadratic elements on the cells of a :class:`~drivedyn.fe.mesh.SolidMesh`: 27-node Lagrange
hexahedra (``ElementHex2``) or 10-node tetrahedra (``ElementTetP2``); integration of order 4
(exact for the mass matrix of affine cells). The *nodes* of the model are the element nodes
(vertices, edge, face and cell nodes), ``nodes`` (n, 3) [m] in the part frame; displacement
dofs are interleaved, ``3 i + d`` for node ``i`` and direction ``d``.

Why scikit-fem: BSD, pure Python on numpy/scipy (installs anywhere pip does), assembles a
vector Lagrange basis in a few lines and exposes the quadrature data we need for stress
recovery; netgen/ngsolve would add an LGPL binary for the same matrices.

Matrices:
* ``K`` (3n, 3n) stiffness [N/m], isotropic Hooke's law;
* ``Ms`` (n, n) scalar consistent mass [kg]: the vector mass matrix is ``Ms (x) I3`` (same
  density in every direction), which the floating-frame invariants use;
* stresses: ``stress_modes(U)`` gives, for displacement columns ``U`` (3n, m), the six
  Cauchy stress components at the nodes (L2 projection of the quadrature-point stresses onto
  the quadratic space, order ``xx, yy, zz, yz, xz, xy``) [Pa per unit of U].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from drivedyn.errors import ModelError
from drivedyn.fe.disk_cache import cached
from drivedyn.fe.mesh import HEX, SolidMesh

VOIGT = ("xx", "yy", "zz", "yz", "xz", "xy")
#: scikit-fem's vertex order of a hexahedron (``MeshHex1``) from the VTK order of
#: :class:`SolidMesh` cells, as ``skfem.io.meshio.from_meshio`` reorders them
HEX_TO_SKFEM = (0, 4, 3, 1, 7, 5, 2, 6)


@dataclass(frozen=True)
class SolidMaterial:
    """Isotropic linear elastic material.

    Attributes:
        youngs_modulus: E [Pa] > 0.
        poisson_ratio: nu [-], -1 < nu < 0.5.
        density: rho [kg/m^3] > 0.
    """

    youngs_modulus: float = 210e9
    poisson_ratio: float = 0.3
    density: float = 7850.0

    def __post_init__(self) -> None:
        for key, lo, hi in (("youngs_modulus", 0.0, math.inf), ("poisson_ratio", -1.0, 0.5),
                            ("density", 0.0, math.inf)):
            v = getattr(self, key)
            if not (isinstance(v, int | float) and math.isfinite(v) and lo < v < hi):
                raise ModelError(f"material.{key}: must be in ({lo}, {hi}), got {v!r}")

    @property
    def lame(self) -> tuple[float, float]:
        """Lame parameters (lambda, mu) [Pa]."""
        E, nu = self.youngs_modulus, self.poisson_ratio
        return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))

    def digest(self) -> str:
        return f"{self.youngs_modulus!r}/{self.poisson_ratio!r}/{self.density!r}"


def von_mises(s: np.ndarray) -> np.ndarray:
    """Von Mises stress of Voigt stresses ``s`` (..., 6) [Pa] -> (...)."""
    xx, yy, zz, yz, xz, xy = (s[..., i] for i in range(6))
    return np.sqrt(0.5 * ((xx - yy) ** 2 + (yy - zz) ** 2 + (zz - xx) ** 2)
                   + 3.0 * (yz**2 + xz**2 + xy**2))


def principal_stresses(s: np.ndarray) -> np.ndarray:
    """Principal stresses (..., 3), descending, of Voigt stresses ``s`` (..., 6) [Pa]:
    closed-form roots of the characteristic cubic (trigonometric form), vectorised."""
    xx, yy, zz, yz, xz, xy = (s[..., i] for i in range(6))
    m = (xx + yy + zz) / 3.0
    a, b, c = xx - m, yy - m, zz - m
    p2 = (a * a + b * b + c * c + 2.0 * (xy * xy + xz * xz + yz * yz)) / 6.0
    p = np.sqrt(p2)
    det = a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where(p > 0, det / (2.0 * np.where(p > 0, p, 1.0) ** 3), 0.0)
    phi = np.arccos(np.clip(r, -1.0, 1.0)) / 3.0
    s1 = m + 2.0 * p * np.cos(phi)
    s3 = m + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
    return np.stack([s1, 3.0 * m - s1 - s3, s3], axis=-1)


class SolidModel:
    """Finite-element model of one part (mesh + material); matrices built on first use.

    Attributes:
        mesh: the :class:`SolidMesh`.
        material: the :class:`SolidMaterial`.
        nodes: (n, 3) node coordinates [m], part frame.
    """

    def __init__(self, mesh: SolidMesh, material: SolidMaterial) -> None:
        self.mesh = mesh
        self.material = material
        self._mesh_key = mesh.digest()  # the cache entries' key (a SHA-1 of the whole mesh)
        # the nodes of a mesh seen before come from the cache folder, and the scikit-fem
        # mesh and bases are then built on first use: a flexible washer loaded from the
        # reduction cache needs none of them (0.1 s of the Type C's five washers with the
        # scikit-fem import, before a bench forks its second side). A mesh is cached only
        # once it has passed the orientation check of ``_checked_nodes``.
        self.nodes = cached("nodes", (self._mesh_key,),
                            lambda: {"nodes": self._checked_nodes()})["nodes"]

    @cached_property
    def _skmesh(self):
        """The scikit-fem mesh of the vertices, built as its meshio reader builds it (without
        importing meshio)."""
        from skfem import MeshHex1, MeshTet1

        hexa = self.mesh.kind == HEX
        cells = self.mesh.cells[:, HEX_TO_SKFEM] if hexa else self.mesh.cells
        return (MeshHex1 if hexa else MeshTet1)(np.ascontiguousarray(self.mesh.points.T),
                                                 np.ascontiguousarray(cells.T))

    @cached_property
    def _element(self):
        from skfem import ElementHex2, ElementTetP2, ElementVector

        return ElementVector(ElementHex2() if self.mesh.kind == HEX else ElementTetP2())

    @cached_property
    def _sbasis(self):
        """Scalar basis of the quadratic element."""
        from skfem import Basis

        return Basis(self._skmesh, self._element.elem, intorder=4)

    def _checked_nodes(self) -> np.ndarray:
        """The element nodes (n, 3) [m], after checking the cells' orientation: scikit-fem
        integrates with |det J|, so a cell inverted relative to the others, or a collapsed
        one, would pass silently."""
        det = self._sbasis.mapping.detDF(self._sbasis.quadrature[0])
        ref = np.sign(np.sum(np.sign(det[:, 0]))) or 1.0  # the majority orientation
        bad = np.flatnonzero(np.any(det * ref <= 1e-12 * np.abs(det).max(), axis=1))
        if bad.size:
            raise ModelError(f"mesh {self.mesh.name!r}: {bad.size} inverted or degenerate "
                             f"cell(s) (Jacobian of the wrong sign or zero), first cell "
                             f"{int(bad[0])}; check the vertex order")
        return np.ascontiguousarray(self._sbasis.doflocs.T)

    @cached_property
    def _vbasis(self):
        """Vector basis (built on first use; it holds the shape-function values and
        gradients of every cell at every quadrature point, the bulk of the memory)."""
        from skfem import Basis

        return Basis(self._skmesh, self._element, intorder=4)

    def release(self) -> None:
        """Drop the large cached data (vector basis, K, M, projector); rebuilt on demand."""
        for key in ("_vbasis", "K", "M", "_projector"):
            self.__dict__.pop(key, None)

    @property
    def n(self) -> int:
        """Number of nodes."""
        return self.nodes.shape[0]

    def digest(self) -> str:
        return self._mesh_key + "/" + self.mesh.kind + "/" + self.material.digest()

    @cached_property
    def K(self) -> sp.csr_matrix:
        """Stiffness (3n, 3n) [N/m]."""
        from skfem import asm
        from skfem.models.elasticity import linear_elasticity

        lam, mu = self.material.lame
        return asm(linear_elasticity(lam, mu), self._vbasis).tocsr()

    @cached_property
    def Ms(self) -> sp.csr_matrix:
        """Scalar consistent mass (n, n) [kg]."""
        from skfem import BilinearForm, asm

        rho = self.material.density

        @BilinearForm
        def mass(u, v, w):
            return rho * u * v

        return asm(mass, self._sbasis).tocsr()

    @cached_property
    def M(self) -> sp.csr_matrix:
        """Vector consistent mass (3n, 3n) [kg], ``Ms (x) I3`` interleaved."""
        return sp.kron(self.Ms, sp.eye(3), format="csr")

    @property
    def mass(self) -> float:
        """Total mass [kg]."""
        return float(self.Ms.sum())

    @cached_property
    def _projector(self):
        from skfem import BilinearForm, asm

        @BilinearForm
        def l2(u, v, w):
            return u * v

        return spla.splu(asm(l2, self._sbasis).tocsc())

    def stress_modes(self, U: np.ndarray) -> np.ndarray:
        """Nodal stresses (n, 6, m) [Pa] of displacement columns ``U`` (3n, m) [m]."""
        from skfem import LinearForm, asm
        from skfem.helpers import sym_grad

        U = np.asarray(U, float).reshape(3 * self.n, -1)
        lam, mu = self.material.lame
        out = np.empty((self.n, 6, U.shape[1]))
        pairs = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))
        for k in range(U.shape[1]):
            eps = sym_grad(self._vbasis.interpolate(U[:, k]))
            tr = eps[0, 0] + eps[1, 1] + eps[2, 2]
            for c, (i, j) in enumerate(pairs):
                sig = 2 * mu * eps[i, j] + (lam * tr if i == j else 0.0)

                @LinearForm
                def rhs(v, w, sig=sig):
                    return sig * v

                out[:, c, k] = self._projector.solve(asm(rhs, self._sbasis))
        return out

    def select(self, axis: str | None = None, value: float | None = None,
               r_min: float | None = None, r_max: float | None = None,
               tol: float | None = None) -> np.ndarray:
        """Indices of the nodes on the plane ``x[axis] = value`` and/or within the radial band
        ``r_min <= sqrt(x^2 + y^2) <= r_max`` (``tol`` [m]: 1e-6 of the part size)."""
        size = float(np.ptp(self.nodes, axis=0).max())
        tol = 1e-6 * size if tol is None else tol
        mask = np.ones(self.n, bool)
        if axis is not None:
            if axis not in ("x", "y", "z"):
                raise ModelError(f"node selection: axis must be 'x', 'y' or 'z', got {axis!r}")
            if value is None:
                raise ModelError("node selection: 'axis' needs a 'value' [m]")
            mask &= np.abs(self.nodes[:, "xyz".index(axis)] - value) <= tol
        r = np.hypot(self.nodes[:, 0], self.nodes[:, 1])
        if r_min is not None:
            mask &= r >= r_min - tol
        if r_max is not None:
            mask &= r <= r_max + tol
        idx = np.flatnonzero(mask)
        if idx.size == 0:
            raise ModelError(f"node selection (axis={axis}, value={value}, r_min={r_min}, "
                             f"r_max={r_max}) selects no node of mesh {self.mesh.name!r}")
        return idx

    def face_areas(self, nodes: np.ndarray) -> np.ndarray:
        """Tributary area [m^2] of each of ``nodes`` on the boundary faces whose nodes all
        belong to ``nodes``: the consistent load of a unit pressure, sum = face area.
        Kept in the cache folder (:mod:`drivedyn.fe.disk_cache`)."""
        nodes = np.asarray(nodes, np.int64).ravel()
        return cached("face_areas", (self._mesh_key, nodes.tobytes()),
                      lambda: {"areas": self._face_areas(nodes)})["areas"]

    def _face_areas(self, nodes: np.ndarray) -> np.ndarray:
        from skfem import FacetBasis, LinearForm, asm

        sel = np.zeros(self.n, bool)
        sel[nodes] = True
        facets = self._skmesh.boundary_facets()
        fverts = self._skmesh.facets[:, facets]
        # vertices of the sk mesh coincide with the first nodes of the scalar basis
        keep = facets[np.all(sel[fverts], axis=0)]
        if keep.size == 0:
            raise ModelError("face_areas: the nodes hold no complete boundary face")
        fb = FacetBasis(self._skmesh, self._sbasis.elem, facets=keep, intorder=4)

        @LinearForm
        def unit(v, w):
            return v

        a = asm(unit, fb)
        return a[nodes]

    def interpolation(self, points: np.ndarray, tol: float = 1e-9) -> sp.csr_matrix:
        """Matrix (k, n) of the quadratic shape functions at ``points`` (k, 3) [m, part
        frame]: ``interpolation(points) @ f`` is the finite-element field of nodal values
        ``f`` (n, ...) at the points. A point on a face or an edge shared by cells takes the
        first cell that holds it (the field is continuous there).

        Each point's cell is found among the cells whose bounding box holds it, by inverting
        the cell's map (Newton) and testing the reference coordinates against the reference
        cell within ``tol``; scikit-fem's own point finder misses points on the boundary
        faces (an annular washer's contact face: one to 25 of 48 points, measured).

        Kept in the cache folder (:mod:`drivedyn.fe.disk_cache`).

        Raises:
            ModelError: a point outside the mesh (named, with its coordinates).
        """
        pts = np.ascontiguousarray(np.asarray(points, float).reshape(-1, 3))

        def compute() -> dict[str, np.ndarray]:
            P = self._interpolation(pts, tol)
            return {"data": P.data, "indices": P.indices, "indptr": P.indptr}

        z = cached("interpolation", (self._mesh_key, pts.tobytes(), repr(float(tol))),
                   compute)
        return sp.csr_matrix((z["data"], z["indices"], z["indptr"]), shape=(len(pts), self.n))

    def _interpolation(self, pts: np.ndarray, tol: float) -> sp.csr_matrix:
        b = self._sbasis
        mesh = self._skmesh
        verts = mesh.p[:, mesh.t]                               # (3, nvert, ncell)
        lo, hi = verts.min(axis=1), verts.max(axis=1)           # (3, ncell)
        centre = verts.mean(axis=1)
        pad = tol * float(np.ptp(mesh.p, axis=1).max())
        hexa = self.mesh.kind == HEX
        cells = np.full(len(pts), -1, np.int64)
        refs = np.zeros((3, len(pts)))

        def inside(X):
            return (np.all((X >= -tol) & (X <= 1 + tol), axis=0) if hexa else
                    np.all(X >= -tol, axis=0) & (X.sum(axis=0) <= 1 + tol))

        # first the nearest cell centre of every point at once (in convex cells, usually
        # the one); the others cell by cell among those whose bounding box holds the point
        near = np.argmin(((centre[:, None, :] - pts.T[:, :, None]) ** 2).sum(axis=0), axis=1)
        try:
            X = b.mapping.invF(pts.T[:, :, None], tind=near)[:, :, 0]
            ok = inside(X)
            cells[ok], refs[:, ok] = near[ok], X[:, ok]
        except Exception:  # scikit-fem's Newton did not converge for some point
            pass
        for i in np.flatnonzero(cells < 0):
            x = pts[i]
            cand = np.flatnonzero(np.all((lo - pad <= x[:, None]) & (x[:, None] <= hi + pad),
                                         axis=0))
            for c in cand[np.argsort(((centre[:, cand] - x[:, None]) ** 2).sum(axis=0))]:
                try:
                    X = b.mapping.invF(x[:, None, None], tind=np.array([c]))[:, :, 0]
                except Exception:  # not this cell
                    continue
                if inside(X)[0]:
                    cells[i], refs[:, i] = c, X[:, 0]
                    break
        miss = np.flatnonzero(cells < 0)
        if miss.size:
            raise ModelError(f"mesh {self.mesh.name!r}: {miss.size} point(s) outside the mesh, "
                             f"first {np.round(pts[miss[0]], 9).tolist()} m")
        phis = np.array([np.asarray(b.elem.gbasis(b.mapping, refs[:, :, None], k, tind=cells)[0])
                         for k in range(b.Nbfun)])               # (nbfun, k, 1)
        rows = np.tile(np.arange(len(pts)), b.Nbfun)
        cols = b.element_dofs[:, cells].ravel()
        return sp.coo_matrix((phis.ravel(), (rows, cols)), shape=(len(pts), self.n)).tocsr()

    def static(self, fixed: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Static displacement (3n,) [m] under nodal forces ``f`` (3n,) [N] with the dofs
        ``fixed`` held at zero."""
        free = np.setdiff1d(np.arange(3 * self.n), fixed)
        u = np.zeros(3 * self.n)
        u[free] = spla.spsolve(self.K[free][:, free].tocsc(), f[free])
        return u

    def to_meshio(self, point_data: dict | None = None):
        """A meshio Mesh of the vertices and linear cells with ``point_data`` given on the
        nodes (the vertex values are taken; the vertices are the first nodes)."""
        import meshio

        nv = self.mesh.points.shape[0]
        cell_type = "hexahedron" if self.mesh.kind == HEX else "tetra"
        pts = self.nodes[:nv]
        pd = {k: np.asarray(v)[:nv] for k, v in (point_data or {}).items()}
        return meshio.Mesh(pts, [(cell_type, self._cells_sk_order())], point_data=pd)

    def _cells_sk_order(self) -> np.ndarray:
        # the skfem mesh renumbers nothing: its vertices are the mesh points in order
        return self.mesh.cells
