"""Craig-Bampton reduction of a solid part for the floating frame of reference.

Interfaces are *rigid spiders* (RBE2): the nodes of interface ``k`` move rigidly with a
6-dof reference point ``P_k`` (``u_i = t_k + theta_k x (X_i - P_k)``). Interface 0 defines
the floating frame: the part's rigid motion is the motion of that spider (the marker the part
is mounted on), so the elastic basis holds the spider at rest. The basis (Craig & Bampton
1968) is, in the frame of interface 0:

* the *constraint modes* of the other interfaces: static shapes for a unit motion of each of
  their 6 dofs with all other spiders held (``-K_ii^-1 K_ib``); their amplitudes are the
  interface motions relative to the frame [m, rad];
* the first ``n_modes`` *fixed-interface modes* (all spiders held), mass-normalised;
* optional *static correction modes* of given load patterns (nodal forces, e.g. the
  pressure patterns of a contact face): the static response with all spiders held, made
  mass-orthogonal to the modes above. Fixed-interface modes alone cannot carry a load applied
  inside the part (a washer's contact pressure excites modes far above the retained ones), so
  its static deformation and stresses would be missed; with these modes the reduced part
  reproduces the full static solution of every load in their span exactly.

``Kr = B^T K B`` and ``Mr = B^T M B`` are the reduced matrices; ``Phi`` (n, 3, nq) the nodal
displacement of each basis vector and ``stress`` (n, 6, nq) its nodal stresses. The check of
a reduction compares the eigenfrequencies of the reduced and the full model (both with the
spiders, and either free or with the frame interface held).

Results are cached on disk (:func:`drivedyn.settings.cache_dir`) keyed by the
mesh, the material, the interfaces and the number of modes: a part is reduced once.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from drivedyn import settings
from drivedyn.errors import ModelError
from drivedyn.fe.solid import SolidModel

CACHE_VERSION = "cb5"
CHECK_MODES = 5  # at most this many retained modes are compared with the full model
# a reduction whose retained fixed-interface modes miss the full model's frequencies (frame
# held, the other spiders free) by more than this is refused: Craig-Bampton keeps its retained
# modes within a fraction of a per cent when its constraint modes span the interfaces'
# motions, so a larger miss is a mesh, interface or basis error; 2 % also stays below the 5 %
# a structural model may miss its test frequencies by (NASA-STD-5002, sec. 4.2)
CHECK_TOL = 0.02
FULL_LIMIT = 600  # internal dofs of the largest part the unreduced option takes


@dataclass(frozen=True)
class Interface:
    """A connection of the part at ``point`` [m] (part frame) over its ``nodes``.

    ``connection="rigid"``: a rigid spider (RBE2), the nodes move rigidly with the point.
    ``connection="average"``: an averaging connection (RBE3), the point's translation is the
    mean of the nodes' and its rotation their least-squares mean rotation about it; the
    nodes stay free (no stiffening), and the forces on the point spread over them as the
    transpose of that average (static modes of these six loads join the basis). The first
    interface of a part (the mounting face) must be rigid. ``name`` names it in messages and
    results."""

    name: str
    nodes: np.ndarray
    point: np.ndarray
    connection: str = "rigid"


def average_map(solid: SolidModel, itf: Interface) -> np.ndarray:
    """RBE3 map (6, 3n): [translation; rotation] of the point from the nodal displacements
    (equal weights): ``t = mean(u_i)``, ``theta = J^-1 mean(rho_i x u_i)`` with
    ``J = mean(|rho_i|^2 I - rho_i rho_i^T)``, ``rho_i`` the node positions from the point."""
    nodes = np.asarray(itf.nodes)
    rho = solid.nodes[nodes] - np.asarray(itf.point, float)
    w = 1.0 / len(nodes)
    J = w * (np.sum(rho * rho) * np.eye(3) - rho.T @ rho)
    if np.linalg.cond(J) > 1e12:
        raise ModelError(f"interface {itf.name!r}: its nodes are collinear; an averaging "
                         "connection needs nodes spread in two directions")
    Ji = np.linalg.inv(J)
    A = np.zeros((6, 3 * solid.n))
    for a in range(3):
        A[a, 3 * nodes + a] = w
    for i, n in enumerate(nodes):
        r = rho[i]
        skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
        A[3:, 3 * n:3 * n + 3] = w * Ji @ skew
    return A


@dataclass
class ReducedPart:
    """A reduced part, ready for :class:`~drivedyn.elements.flexible.FlexibleBody`.

    All arrays in the frame of interface 0 (origin ``interfaces[0].point``, axes of the part
    frame).

    Attributes:
        name: part name.
        X: (n, 3) node positions [m].
        Ms: (n, n) scalar consistent mass [kg] (CSR).
        Phi: (n, 3, nq) nodal displacements of the basis [m per unit coordinate].
        Kr, Mr: (nq, nq) reduced stiffness [N/m...] and mass [kg...].
        stress: (n, 6, nq) nodal stresses of the basis [Pa per unit coordinate].
        n_constraint: number of constraint-mode coordinates (6 per rigid interface after
            the first); they come first in the basis.
        maps: (k - 1, 6, nq) translation [m] and small rotation [rad] of each interface after
            the first, relative to the frame, per coordinate (a selection of the constraint
            coordinates for a rigid one, the averaged basis for an averaging one).
        interfaces: the spiders (points relative to interface 0).
        freq_fixed: (n_modes,) fixed-interface eigenfrequencies [Hz].
        solid: the :class:`SolidModel` (None when loaded from the cache).
        key: cache key.
    """

    name: str
    X: np.ndarray
    Ms: sp.csr_matrix
    Phi: np.ndarray
    Kr: np.ndarray
    Mr: np.ndarray
    stress: np.ndarray
    n_constraint: int
    interfaces: list[Interface]
    freq_fixed: np.ndarray
    cells: np.ndarray
    kind: str
    maps: np.ndarray | None = None
    solid: SolidModel | None = None
    key: str = ""
    check: np.ndarray | None = None  # (2, n): full and reduced frequencies [Hz], frame held

    def check_text(self) -> str:
        """The printed check of the reduction: the retained eigenfrequencies (at most
        :data:`CHECK_MODES`) of the full and the reduced model, both with the spiders and the
        mounting interface held."""
        if self.check is None or self.check.shape[1] == 0:
            return f"part {self.name}: {self.nq} coordinates (no frequency check)"
        full, red = self.check
        rows = ", ".join(f"{f:.4g}/{r:.4g} ({100 * (r / f - 1):+.2f} %)"
                         for f, r in zip(full, red, strict=True))
        return (f"part {self.name}: {3 * self.n} FE dofs -> {self.nq} coordinates "
                f"({self.n_constraint} constraint, {len(self.freq_fixed)} fixed-interface, "
                f"{self.nq - self.n_constraint - len(self.freq_fixed)} static); frequencies "
                f"full/reduced [Hz], mounting face held: {rows}")

    @property
    def nq(self) -> int:
        return self.Phi.shape[2]

    @property
    def n(self) -> int:
        return self.X.shape[0]

    @property
    def mass(self) -> float:
        return float(self.Ms.sum())

    def basis_matrix(self) -> np.ndarray:
        """B (3n, nq): the basis with interleaved dofs."""
        return self.Phi.reshape(3 * self.n, self.nq)


def face_load_patterns(solid: SolidModel, nodes: np.ndarray, axis: int = 2,
                       friction: int = 4) -> np.ndarray:
    """Nodal forces (3n, 4 + friction) [N] of unit tractions on the boundary face held by
    ``nodes`` whose normal is ``axis``: four normal patterns (uniform, linear in each in-plane
    coordinate (tilt) and linear in the radius about the axis (conicity)), each scaled to a
    resultant or moment of order 1 N; then ``friction`` (0, 1 or 4) circumferential tractions
    about the axis (through the part origin) with the first ``friction`` of the same weights.
    The friction of a face spinning on its counter face is ``mu p`` along the circle: with 4
    the static modes carry every pressure in the span of the normal patterns together with
    its friction; with 1 the friction of a uniform pressure (the torque the friction puts
    through the part); with 0 the friction tractions do not deform the part. The load
    patterns of a washer face for :func:`craig_bampton`."""
    if friction not in (0, 1, 4):
        raise ModelError(f"face_load_patterns: friction = {friction!r}, expected 0, 1 or 4 "
                         "circumferential patterns")
    a = solid.face_areas(nodes)
    X = solid.nodes[nodes]
    u, v = (k for k in range(3) if k != axis)
    r = np.hypot(X[:, u], X[:, v])
    size = max(float(np.abs(X[:, [u, v]]).max()), 1e-12)
    rm = float(np.sum(a * r) / a.sum())
    weights = (np.ones(len(nodes)), X[:, u] / size, X[:, v] / size, (r - rm) / size)
    out = np.zeros((3 * solid.n, 4 + friction))
    for j, w in enumerate(weights):
        out[3 * nodes + axis, j] = w * a / a.sum()
    rs = np.maximum(r, 1e-12 * size)
    for j, w in enumerate(weights[:friction], start=4):
        # unit circumferential direction e_theta = (-v, u) / r in the (u, v) plane
        out[3 * nodes + u, j] = -X[:, v] / rs * w * a / a.sum()
        out[3 * nodes + v, j] = X[:, u] / rs * w * a / a.sum()
    return out


def _spider_map(solid: SolidModel, interfaces: Sequence[Interface]):
    """T (3n, nf + 6k) with u = T [u_internal; s_1..s_k] and the internal dof indices."""
    n = solid.n
    owner = np.full(n, -1)
    for k, itf in enumerate(interfaces):
        if np.any(owner[itf.nodes] >= 0):
            other = interfaces[int(owner[itf.nodes][owner[itf.nodes] >= 0][0])].name
            raise ModelError(f"interfaces {other!r} and {itf.name!r} share nodes")
        owner[itf.nodes] = k
    internal = np.flatnonzero(owner < 0)
    idof = (3 * internal[:, None] + np.arange(3)).ravel()
    nf = idof.size
    rows, cols, vals = [idof, ], [np.arange(nf)], [np.ones(nf)]
    for k, itf in enumerate(interfaces):
        c0 = nf + 6 * k
        d = solid.nodes[itf.nodes] - itf.point
        for a in range(3):
            rows.append(3 * itf.nodes + a)
            cols.append(np.full(len(itf.nodes), c0 + a))
            vals.append(np.ones(len(itf.nodes)))
        # theta x d: component a = e_abc theta_b d_c
        for a, b, c, sgn in ((0, 1, 2, 1), (0, 2, 1, -1), (1, 2, 0, 1), (1, 0, 2, -1),
                             (2, 0, 1, 1), (2, 1, 0, -1)):
            rows.append(3 * itf.nodes + a)
            cols.append(np.full(len(itf.nodes), c0 + 3 + b))
            vals.append(sgn * d[:, c])
    T = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(3 * n, nf + 6 * len(interfaces)))
    return T, nf


def _cache_dir() -> Path:
    return settings.cache_dir()


def craig_bampton(solid: SolidModel, interfaces: Sequence[Interface], n_modes: int,
                  name: str = "part", cache: bool = True,
                  loads: np.ndarray | None = None,
                  check_tol: float | None = CHECK_TOL) -> ReducedPart:
    """Reduce ``solid`` with ``interfaces`` (the first, rigid, defines the floating frame),
    ``n_modes`` fixed-interface modes and the static correction modes of the nodal load
    patterns ``loads`` (3n, m) [N] (see the module docstring). ``n_modes="all"`` keeps every
    internal dof: the unreduced part in the floating frame (small parts only, up to
    :data:`FULL_LIMIT` internal dofs; static modes are then in the span and dropped).

    The reduction carries its frequency check (:attr:`ReducedPart.check`): the first
    ``min(CHECK_MODES, n_modes)`` eigenfrequencies of the reduced and the full model, frame
    interface held. The static correction modes represent loads, not vibration modes, so the
    frequencies above the retained ones are not compared. A retained frequency off by more
    than ``check_tol`` (relative; :data:`CHECK_TOL`, ``None``: not checked) raises
    :class:`ModelError` naming the mode."""
    if not interfaces:
        raise ModelError(f"part {name!r}: at least one interface (the mounting face) is needed")
    for itf in interfaces:
        if itf.connection not in ("rigid", "average"):
            raise ModelError(f"part {name!r}, interface {itf.name!r}: connection must be "
                             f"'rigid' or 'average', got {itf.connection!r}")
    if interfaces[0].connection != "rigid":
        raise ModelError(f"part {name!r}: the first interface (the mounting face) must be "
                         "rigid")
    averages = [(k, average_map(solid, itf)) for k, itf in enumerate(interfaces)
                if itf.connection == "average"]
    rigid = [itf for itf in interfaces if itf.connection == "rigid"]
    full = n_modes == "all"
    if not full and (isinstance(n_modes, str) or int(n_modes) != n_modes or n_modes < 0):
        raise ModelError(f"part {name!r}: n_modes must be an integer >= 0 or 'all', got "
                         f"{n_modes!r}")
    n_modes = -1 if full else int(n_modes)
    h = hashlib.sha1(f"{CACHE_VERSION}/{solid.digest()}/{n_modes}".encode())
    for itf in interfaces:
        h.update(np.asarray(itf.nodes, np.int64).tobytes())
        h.update(np.asarray(itf.point, float).tobytes())
        h.update(itf.connection.encode())
    loads = np.zeros((3 * solid.n, 0)) if loads is None else \
        np.asarray(loads, float).reshape(3 * solid.n, -1)
    # the forces on an averaging interface spread as the transpose of its average
    loads = np.hstack([loads, *[A.T for _, A in averages]])
    h.update(np.ascontiguousarray(loads).tobytes())
    key = h.hexdigest()
    path = _cache_dir() / "reduction" / f"{key}.npz"
    if cache and path.is_file():
        try:
            part = _load(path, name, interfaces, solid, key)
        except (OSError, ValueError, KeyError):
            pass  # a damaged cache entry is recomputed
        else:
            return _checked(part, check_tol)
    T, nf = _spider_map(solid, rigid)
    Ks = (T.T @ solid.K @ T).tocsc()
    Ms = (T.T @ solid.M @ T).tocsc()
    k = len(rigid)
    bnd = np.arange(nf + 6, nf + 6 * k)        # other interfaces
    inn = np.arange(nf)
    Kii = Ks[inn][:, inn].tocsc()
    if full:
        if nf > FULL_LIMIT:
            raise ModelError(f"part {name!r}: n_modes = 'all' keeps every one of its {nf} "
                             f"internal dofs, more than the {FULL_LIMIT} the unreduced option "
                             "takes (its cost grows as the square); give a number of modes")
        n_modes = nf
    if n_modes > nf:
        raise ModelError(f"part {name!r}: n_modes = {n_modes} exceeds the {nf} internal dofs")
    lu = spla.splu(Kii)
    cols = []
    if bnd.size:
        Psi = -lu.solve(Ks[inn][:, bnd].toarray())
        C = np.zeros((nf + 6 * k, bnd.size))
        C[inn] = Psi
        C[bnd, np.arange(bnd.size)] = 1.0
        cols.append(C)
    freq = np.zeros(0)
    if n_modes:
        Mii = Ms[inn][:, inn].tocsc()
        # a fixed start vector: eigsh starts from a random one, and in degenerate pairs
        # (axisymmetric parts) it would return another basis of the pair on every run
        if n_modes >= nf - 1:  # every mode: the unreduced part (dense, small parts only)
            import scipy.linalg as sla

            w2, V = sla.eigh(Kii.toarray(), Mii.toarray())
            w2, V = w2[:n_modes], V[:, :n_modes]
        else:
            try:
                w2, V = spla.eigsh(Kii, k=n_modes, M=Mii, sigma=0.0, which="LM",
                                   v0=np.linspace(1.0, 2.0, nf))
            except (spla.ArpackError, spla.ArpackNoConvergence) as exc:
                raise ModelError(f"part {name!r}: no fixed-interface modes ({exc}); check the "
                                 "material (density, modulus) and the mesh") from None
        order = np.argsort(w2)
        w2, V = w2[order], V[:, order]
        V /= np.sqrt(np.einsum("ij,ij->j", V, Mii @ V))
        F = np.zeros((nf + 6 * k, n_modes))
        F[inn] = V
        cols.append(F)
        freq = np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi)
    if loads.shape[1]:
        Mii = Ms[inn][:, inn].tocsc()
        fs = np.asarray(T.T @ loads)[inn]
        S = lu.solve(fs)
        # mass-orthogonal to the fixed-interface modes and to each other (two passes of
        # Gram-Schmidt), normalised to unit modal mass; dependent patterns are dropped
        V = cols[-1][inn] if n_modes else np.zeros((nf, 0))
        keep = []
        for j in range(S.shape[1]):
            x = S[:, j].copy()
            scale0 = np.sqrt(max(float(x @ (Mii @ x)), 0.0))
            for _ in range(2):
                for Q in (V, *keep):
                    Q2 = Q.reshape(nf, -1)
                    x -= Q2 @ (Q2.T @ (Mii @ x))
            m = np.sqrt(max(float(x @ (Mii @ x)), 0.0))
            if m > 1e-8 * scale0:
                keep.append((x / m)[:, None])
        if keep:
            F = np.zeros((nf + 6 * k, len(keep)))
            F[inn] = np.hstack(keep)
            cols.append(F)
    Bs = np.hstack(cols) if cols else np.zeros((nf + 6 * k, 0))
    B = np.asarray(T @ Bs)
    Kr = B.T @ (solid.K @ B)
    Mr = B.T @ (solid.M @ B)
    stress = solid.stress_modes(B) if B.shape[1] else np.zeros((solid.n, 6, 0))
    # interface maps (rigid: the constraint coordinates; average: the averaged basis)
    maps = np.zeros((len(interfaces) - 1, 6, B.shape[1]))
    avg = dict(averages)
    r = 0
    for j, itf in enumerate(interfaces[1:], start=1):
        if itf.connection == "rigid":
            maps[j - 1, :, 6 * r:6 * r + 6] = np.eye(6)
            r += 1
        else:
            maps[j - 1] = avg[j] @ B
    P0 = np.asarray(interfaces[0].point, float)
    part = ReducedPart(
        name=name, X=solid.nodes - P0, Ms=solid.Ms, Phi=B.reshape(solid.n, 3, -1),
        Kr=0.5 * (Kr + Kr.T), Mr=0.5 * (Mr + Mr.T), stress=stress, n_constraint=bnd.size,
        interfaces=[Interface(i.name, np.asarray(i.nodes), np.asarray(i.point, float) - P0,
                              i.connection) for i in interfaces],
        freq_fixed=freq, cells=solid.mesh.cells, kind=solid.mesh.kind, maps=maps, solid=solid,
        key=key)
    nc = min(CHECK_MODES, len(freq))
    part.check = np.array(frequency_check(part, solid, rigid, nc, free=False)) if nc else \
        np.zeros((2, 0))
    if cache:
        _save(path, part)
    solid.release()  # the reduced part keeps what it needs (Ms, basis, stresses)
    return _checked(part, check_tol)


def _checked(part: ReducedPart, tol: float | None) -> ReducedPart:
    """``part`` if its retained frequencies are within ``tol`` of the full model's.

    The error names the lowest mode beyond ``tol``: a part's modes often come in degenerate
    pairs (a square bar's two bending directions) whose errors differ only by round-off, so
    the largest error would name either mode of the pair depending on the machine."""
    if tol is None or part.check is None or part.check.shape[1] == 0:
        return part
    full, red = part.check
    beyond = np.flatnonzero(np.abs(red / full - 1.0) > tol)
    if beyond.size:
        k = int(beyond[0])
        raise ModelError(
            f"part {part.name!r}: the reduced model's mode {k + 1} is at {red[k]:.5g} Hz, the "
            f"full model's at {full[k]:.5g} Hz ({100 * (red[k] / full[k] - 1):+.2f} %, more "
            f"than the {100 * tol:g} % allowed): the basis misses the part's dynamics; "
            "retain more modes or check the interfaces")
    return part


def _save(path: Path, part: ReducedPart) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
    Ms = part.Ms.tocsr()
    np.savez(tmp, X=part.X, Ms_data=Ms.data, Ms_indices=Ms.indices, Ms_indptr=Ms.indptr,
             Phi=part.Phi, Kr=part.Kr, Mr=part.Mr, stress=part.stress,
             n_constraint=part.n_constraint, freq=part.freq_fixed, cells=part.cells,
             kind=part.kind, check=part.check if part.check is not None else np.zeros((2, 0)),
             maps=part.maps)
    os.replace(tmp, path)


def _load(path: Path, name: str, interfaces, solid, key) -> ReducedPart:
    with np.load(path, allow_pickle=False) as z:
        n = z["X"].shape[0]
        Ms = sp.csr_matrix((z["Ms_data"], z["Ms_indices"], z["Ms_indptr"]), shape=(n, n))
        P0 = np.asarray(interfaces[0].point, float)
        return ReducedPart(
            name=name, X=z["X"], Ms=Ms, Phi=z["Phi"], Kr=z["Kr"], Mr=z["Mr"],
            stress=z["stress"], n_constraint=int(z["n_constraint"]),
            interfaces=[Interface(i.name, np.asarray(i.nodes), np.asarray(i.point, float) - P0,
                                  i.connection) for i in interfaces],
            freq_fixed=z["freq"], cells=z["cells"], kind=str(z["kind"]), solid=solid, key=key,
            check=z["check"], maps=z["maps"])


def frequency_check(part: ReducedPart, solid: SolidModel, interfaces: Sequence[Interface],
                    n: int = 5, free: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """First ``n`` eigenfrequencies [Hz] of the full model with the spiders and of the reduced
    model: with the frame interface held (``free=False``, the part on a heavy mount) or
    free-free (``free=True``, rigid-body modes skipped). Returns (full, reduced). Averaging
    interfaces add no constraint to either model."""
    T, nf = _spider_map(solid, [i for i in interfaces if i.connection == "rigid"])
    Ks = (T.T @ solid.K @ T).tocsc()
    Ms = (T.T @ solid.M @ T).tocsc()
    keep = np.arange(Ks.shape[0]) if free else np.setdiff1d(np.arange(Ks.shape[0]),
                                                              np.arange(nf, nf + 6))
    Kk = Ks[keep][:, keep].tocsc()
    Mk = Ms[keep][:, keep].tocsc()
    nr = n + (6 if free else 0)
    shift = -(2 * np.pi * 1.0) ** 2 if free else 0.0
    # a few more than needed: with clusters of close or repeated modes (axisymmetric parts)
    # ARPACK may miss one of the last of a set of exactly nr
    extra = min(nr + 6, Kk.shape[0] - 1)
    w2 = spla.eigsh(Kk, k=extra, M=Mk, sigma=shift, which="LM", return_eigenvectors=False)
    full = np.sqrt(np.maximum(np.sort(w2), 0.0))[nr - n:nr] / (2 * np.pi)
    B = part.basis_matrix()
    if free:
        X = part.X
        R6 = np.zeros((3 * part.n, 6))
        for a in range(3):
            R6[a::3, a] = 1.0
        R6[1::3, 3], R6[2::3, 3] = -X[:, 2], X[:, 1]
        R6[0::3, 4], R6[2::3, 4] = X[:, 2], -X[:, 0]
        R6[0::3, 5], R6[1::3, 5] = -X[:, 1], X[:, 0]
        B = np.hstack([R6, B])
    import scipy.linalg as sla

    Kr = B.T @ (solid.K @ B)
    Mr = B.T @ (solid.M @ B)
    wr = sla.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T), eigvals_only=True)
    red = np.sqrt(np.maximum(np.sort(wr), 0.0))[(6 if free else 0):][:n] / (2 * np.pi)
    return full, red
