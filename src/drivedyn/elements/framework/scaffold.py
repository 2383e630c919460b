"""The kernel scaffold: what every element family's kernel does besides its physics.

A family writes one kernel with the calling convention of
:mod:`drivedyn.elements.framework.contract` (its parameters, then the common arguments); its
body is the loop over the elements (the physics)::

    L12 = LOCAL_SIZE_12                         # entries of local_arrays(12, 0)
    WORK_SIZE = L12 + 12 + sc.WORKSPACE_SIZE   # the group passes np.zeros(WORK_SIZE)

    @njit(cache=True)
    def spring_kernel(stiff, damp, work, lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv,
                      t, Tn, cM, cC, cK, mode, want, r, rabs, data, eout, aux):
        C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode,
             want, r, rabs, data, eout, aux)
        buf = sc.work_buffer(work, WORK_SIZE)   # work arrays: views of the group's buffer
        L, vl = local_arrays_at(buf, 0, 12, 0), carve(buf, L12, 12)
        ws, wv = sc.workspace_at(buf, L12 + 12)
        full = sc.full_pass(want, mode)         # the element matrices are wanted
        rq, rl, M, Cd, K, G = L                 # local residual and matrices
        x, R, v, vd, lam, es, tfv, t = sc.state(C)
        for e in range(sc.count(C)):
            nA, nB = sc.pair(C, e)
            ...                                 # fill rq (and K, Cd... if full)
            sc.scatter(C, L, e, 2, full)
            sc.energy(C, e, 0.0, V, 0.0, P_dis)
            sc.report(C, e, (s, q, qd))

``C`` is the common arguments in the order of the kernel contract (fields named by the
constants below, read through the helpers); the work arrays are never allocated inside the
element loop (small allocations cost more than the maths), and best not at all: a kernel can
carve every work array (:func:`drivedyn.elements.framework.work_arrays.carve`) from a buffer
allocated with its group, its last parameter ``work`` (:func:`work_buffer`; the ``*_at``
helpers below and ``local_arrays_at`` carve the usual sets). Every family does so but the
flexible bodies and their ties (their own work arrays; ``tests/elements/test_work_arrays``
checks that the others allocate nothing when the stepping loop calls them): allocating per call
(``malloc``, ``free``, numba's wrapper) took 13 % of the Type C vehicle configuration's run
(measured with ``perf``). The buffer also reaches the kernel without its memory owner (the
kernel table passes it so), and so do the views carved from it: a view of an array the
kernel allocated, or its passing to a helper that is not inlined, costs an atomic increment
and decrement of the owner's count (the beam race, 100 elements: 22 % of the run less
with the beams' buffer). Families that allocate per call (``local_arrays``,
:func:`grad_hess`...) get one allocation per helper: each carves its arrays from one zeroed
buffer, and vectors of one length are the rows of one array (``V = np.zeros((k, 12))``;
``V[0]``...). The loop skips its matrix branches when ``full`` (:func:`full_pass`) is false.

The loop is the kernel's own body, not a function the kernel calls: numba compiles a called
function on its own, then links its code into the caller and optimises and generates all of
it again, and a function inlined by numba (``inline="always"``) has its IR deep-copied block
by block with its whole scope at every call site (numba issue #8989). Either cost seconds of
a first compilation per family (measured on the Type C bench's kernels: the joints 20.0 ->
15.0 s, the gear pairs 30.3 -> 20.1 s). Small helpers (those below, the primitives) stay
inlined. The kernel stays a module-level function of the family's module, so editing the
physics invalidates its cache (a kernel made by a closure recompiles in every process:
measured).

Two rules keep the loop fast (measured: breaking them doubled the time of a spring group):
unpack the work arrays and the arrays of ``C`` (:func:`state`) *before* the element loop, not
per element (a tuple unpacked inside the loop is reference-counted on every element); the
per-element helpers below read only scalars and rows of ``C``. A helper that takes a tuple
(``C``, a law table row...) reads it in a straight-line prefix only (a tuple still needed
after a branch is reference-counted on every call: a ``full_pass(C)`` with a short-circuit
``or`` cost 0.2 us per kernel call; it takes the two scalars instead). No Python runs per
element: one kernel call evaluates the whole group.

Numba's cache checks only the source file of the cached function: after editing this module
(or :mod:`~drivedyn.elements.framework.contract`,
:mod:`~drivedyn.elements.framework.primitives`), kernels cached from the family modules still
hold the old code until their caches are removed
(``__pycache__/*.nbi``, ``*.nbc``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from drivedyn.elements.framework.contract import MODE_ACC, scatter_element
from drivedyn.elements.framework.primitives import gather_v
from drivedyn.elements.framework.work_arrays import carve

# fields of the common argument tuple C (the kernel contract's trailing arguments)
LNODES, DOFS, KMAP, EOFF = 0, 1, 2, 3
X, ROT, VEL, ACC, LAM, ES, TFV, TIME = 4, 5, 6, 7, 8, 9, 10, 11
TN, CM, CC, CK, MODE, WANT = 12, 13, 14, 15, 16, 17
RES, RABS, DATA, EOUT, AUX = 18, 19, 20, 21, 22


# --- the element loop -------------------------------------------------------------------------


@njit(cache=True, inline="always")
def full_pass(want, mode):
    """True if an evaluation needs the element matrices (matrix wanted, or MODE_ACC)."""
    return want or mode == MODE_ACC


@njit(cache=True, inline="always")
def count(C):
    """Number of elements of the group."""
    return C[LNODES].shape[0]


# --- reading the common arguments ---------------------------------------------------------------


@njit(cache=True, inline="always")
def state(C):
    """``(x, R, v, vd, lam, es, tfv, t)``: node positions and rotations, velocities,
    accelerations, multipliers, element state, time functions, time."""
    return C[X], C[ROT], C[VEL], C[ACC], C[LAM], C[ES], C[TFV], C[TIME]


@njit(cache=True, inline="always")
def mode_of(C):
    """The evaluation mode (``MODE_DYN``, ``MODE_ACC``, ``MODE_VEL``)."""
    return C[MODE]


@njit(cache=True, inline="always")
def wants_matrix(C):
    """True if the iteration matrix is wanted (``want``)."""
    return C[WANT]


@njit(cache=True, inline="always")
def node(C, e, a):
    """Node index of local node ``a`` of element ``e`` (``nn``: the ground)."""
    return C[LNODES][e, a]


@njit(cache=True, inline="always")
def pair(C, e):
    """Node indices ``(nA, nB)`` of a two-node element."""
    ln = C[LNODES]
    return ln[e, 0], ln[e, 1]


@njit(cache=True, inline="always")
def state_offset(C, e):
    """Offset of element ``e``'s internal state in ``es``."""
    return C[EOFF][e]


@njit(cache=True, inline="always")
def first_dof(C, e):
    """Global equation index of element ``e``'s first local dof (one-node elements)."""
    return C[DOFS][e, 0]


@njit(cache=True, inline="always")
def velocities(C, e, nd, out):
    """Local velocities (nd,) of element ``e`` into ``out`` (0 for ground dofs)."""
    gather_v(C[VEL], C[DOFS][e], nd, out)


@njit(cache=True, inline="always")
def accelerations(C, e, nd, out):
    """Local accelerations (nd,) of element ``e`` into ``out`` (0 for ground dofs)."""
    gather_v(C[ACC], C[DOFS][e], nd, out)


@njit(cache=True, inline="always")
def multiplier(C, e, nd, i):
    """Multiplier ``i`` of element ``e`` (local dof ``nd + i``)."""
    lam = C[LAM]
    return lam[C[DOFS][e, nd + i] - (C[RES].shape[0] - lam.shape[0])]


# --- writing the results ------------------------------------------------------------------------


@njit(cache=True, inline="always")
def scatter(C, L, e, nnode, full):
    """Add element ``e``'s local residual and (if ``full`` and wanted) matrices ``L = (rq,
    rl, M, C, K, G)`` into the global arrays
    (:func:`~drivedyn.elements.framework.contract.scatter_local`)."""
    rq, rl, M, Cd, K, G = L
    scatter_element(rq, rl, M, Cd, K, G, nnode, C[LNODES][e], C[DOFS][e], C[KMAP][e], C[TN],
                    C[CM], C[CC], C[CK], C[MODE], C[WANT], full, C[RES], C[RABS], C[DATA])


@njit(cache=True, inline="always")
def clear(L, full):
    """Zero the local residual ``rq, rl`` and, if ``full``, the matrices ``M, C, K, G``."""
    rq, rl, M, Cd, K, G = L
    rq[:] = 0.0
    rl[:] = 0.0
    if full:
        M[:, :] = 0.0
        Cd[:, :] = 0.0
        K[:, :] = 0.0
        G[:, :] = 0.0


@njit(cache=True, inline="always")
def energy(C, e, kinetic, potential, supplied, dissipated):
    """Element ``e``'s energy account: kinetic [J] and potential [J] energy, power supplied
    [W] and power dissipated [W]."""
    eout = C[EOUT]
    eout[e, 0] = kinetic
    eout[e, 1] = potential
    eout[e, 2] = supplied
    eout[e, 3] = dissipated


@njit(cache=True, inline="always")
def report(C, e, values):
    """Element ``e``'s outputs ``aux[e, 0:len(values)]`` (a tuple of floats). The tuple costs
    a few ns per element over plain ``aux[e, k] = ...`` stores (measured: 7 ns for the 19
    outputs of a gear pair), which the hottest kernels write directly."""
    aux = C[AUX]
    for k in range(len(values)):
        aux[e, k] = values[k]


# --- work arrays ------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def grad_hess(n):
    """A gradient (n,) and its derivative (n, n), zeroed."""
    return grad_hess_at(np.zeros(grad_hess_size(n)), 0, n)  # one allocation


@njit(cache=True, inline="always")
def angle_work():
    """Work arrays of :func:`~drivedyn.elements.framework.primitives.prim_angle`:
    ``gs, Hs, gc, Hc``."""
    return angle_work_at(np.zeros(ANGLE_WORK_SIZE), 0)  # one allocation


#: entries of :func:`workspace_at` and :func:`angle_work_at`
WORKSPACE_SIZE = 96
ANGLE_WORK_SIZE = 312


@njit(cache=True, inline="always")
def grad_hess_size(n: int) -> int:
    """Entries of :func:`grad_hess_at` ``n``."""
    return n + n * n


#: entries of ``grad_hess(12)`` (from the plain function: nothing compiled at import)
GRAD_HESS_SIZE_12 = grad_hess_size.py_func(12)


@njit(cache=True, inline="always")
def grad_hess_at(buf, o, n):
    """:func:`grad_hess` as views of ``buf`` from entry ``o``."""
    return carve(buf, o, n), carve(buf, o + n, (n, n))


@njit(cache=True, inline="always")
def angle_work_at(buf, o):
    """:func:`angle_work` as views of ``buf`` from entry ``o`` (:data:`ANGLE_WORK_SIZE`)."""
    return (carve(buf, o, 12), carve(buf, o + 12, (12, 12)), carve(buf, o + 156, 12),
            carve(buf, o + 168, (12, 12)))


@njit(cache=True, inline="always")
def workspace_at(buf, o):
    """:func:`workspace` as views of ``buf`` from entry ``o`` (:data:`WORKSPACE_SIZE`)."""
    return carve(buf, o, (8, 3, 3)), carve(buf, o + 72, (8, 3))


@njit(cache=True, inline="always")
def work_buffer(work, n):
    """The group's work buffer ``work`` (a kernel parameter, allocated zeroed with the
    group), or a new zeroed buffer of ``n`` entries if it is shorter.

    A kernel that carves its work arrays from it allocates nothing per call.

    Not zeroed at each call: the kernels set every work array they read within the element
    that reads it (or never write it: it stays zero), so an evaluation does not depend on
    what earlier ones left in the buffer (``tests/elements/test_work_arrays.py`` evaluates
    every element case after evaluations at other states, with and without the matrix,
    against a fresh buffer). Zeroing it at each call was 4.6 % of the Type C vehicle
    configuration's run (the gear pairs' 2454 entries at every evaluation)."""
    if work.shape[0] < n:
        return np.zeros(n)
    return work


@njit(cache=True, inline="always")
def workspace():
    """Work arrays ``ws`` (8, 3, 3) and ``wv`` (8, 3) of the kinematic primitives."""
    return workspace_at(np.empty(WORKSPACE_SIZE), 0)  # one allocation
