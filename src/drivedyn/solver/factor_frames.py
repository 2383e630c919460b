"""Solves with a factorisation of an earlier configuration, in the node frames it was taken in.

A node's rotation unknowns are increments in the node's own frame, so the iteration matrix
couples a spinning part's rotation columns with the rest of the model through the part's
rotation: a factorisation taken ``Q = R_fac^T R`` earlier sees them turned by ``Q`` (in the
RWD launch, 2.2 degrees of the pinion's spin change the carrier-pinion entries by 13 %, and
that change alone kept the stale iterations from contracting: ``docs/benchmark-log.md``).
Turned back, the present matrix is close to ``T^T A_fac T``, with ``T`` the block-diagonal
rotation holding ``Q`` on the node's rotation unknowns (the identity elsewhere), and a
solve of ``A delta = b`` with the old factors is

    y = A_fac^-1 (T b),    delta = T^T y,

that is: each chosen node's three rotation entries of the right-hand side turned by ``Q``
before the solve and the solution's turned back by ``Q^T`` after it (:func:`to_frames`,
:func:`from_frames`). The nodes are chosen from the matrices (:func:`choose_frames`, at
every factorisation): a node is turned if its rotation columns changed since the last
factorisation by less than :data:`TURN_GAIN` times as much when compared in the turned
frame as when compared as they are.

Only rigid bodies' nodes are candidates. A beam's nodes pass the column test (the shaft of
the beam race: the matrix distance fell to 0.08 of its body-frame value with its nodes
turned), but the run got worse: 35 105 Newton iterations and 6791 factorisations against
27 583 and 5792, the stale iterations' contraction staying at 0.72, set by the bearings'
and the drive's rows. Measured with the candidates (benchmarks, interleaved): the RWD TORSEN
launch 3045 -> 2352 factorisations and 9429 -> 8300 Newton iterations (the pinion chosen),
wall -16 to -24 %; the 4WD launch 1180 -> 1108 factorisations (the propeller shafts chosen),
its rolling start 2033 -> 2178, both walls within their noise; the Type C bench (two
planets chosen) 0.6-0.8 % more steps and 0.4-1.4 % more factorisations; the Type C vehicle
example and the beam race unchanged (the same counts).

``frames`` is a tuple ``(flags, Rf, prev, have, So, Sn, rows, mark, Q, candidates)``:
    flags (nn,) uint8: node turned (1) in the solves;
    candidates (nn,) uint8: a rigid body's node (1), which may be turned;
    Rf (nn, 3, 3): the candidates' rotations at the last factorisation;
    prev (nnz,): the matrix of the last factorisation (CSC data; the candidates' rotation
    columns only);
    have (2,) int64: ``prev`` and ``Rf`` hold a factorisation (1), and the number of nodes
    turned;
    So, Sn (neq, 3), rows (neq,) int64, mark (neq,) uint8, Q (3, 3): work arrays (``So``,
    ``Sn`` and ``mark`` zero between calls).
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: a node's rotation columns are compared with the last factorisation's in the turned frame
#: and as they are; the node is turned if the first difference is below TURN_GAIN times the
#: second (a clear gain, not noise between two nearly equal figures; 0.25 and 0.5 give the
#: same steps, iterations and factorisations on the RWD and 4WD launches)
TURN_GAIN = 0.25


def frame_arrays(candidates: np.ndarray, nnz: int, neq: int) -> tuple:
    """The ``frames`` arrays (module docstring) for the nodes that may be turned
    (``candidates``, bool (nn,)) and a matrix of ``nnz`` entries and ``neq`` rows."""
    nn = candidates.shape[0]
    return (np.zeros(nn, np.uint8), np.zeros((nn, 3, 3)), np.zeros(nnz),
            np.zeros(2, np.int64), np.zeros((neq, 3)), np.zeros((neq, 3)),
            np.zeros(neq, np.int64), np.zeros(neq, np.uint8), np.zeros((3, 3)),
            candidates.astype(np.uint8))


@njit(cache=True)
def _turn(Rf, R, i, Q):
    """Q = Rf[i]^T R[i] (3, 3)."""
    for a in range(3):
        for b in range(3):
            Q[a, b] = Rf[i, 0, a] * R[i, 0, b] + Rf[i, 1, a] * R[i, 1, b] + \
                Rf[i, 2, a] * R[i, 2, b]


@njit(cache=True)
def choose_frames(data, indices, indptr, R, frames):
    """After a factorisation of the matrix ``data`` (CSC, pattern ``indices, indptr``) at
    node rotations ``R`` (nn + 1, 3, 3): choose the nodes turned in its solves by comparing
    each candidate's rotation columns with the last factorisation's (module docstring), then
    keep this matrix's columns and ``R`` of the candidates as the last factorisation's."""
    flags, Rf, prev, have, So, Sn, rows, mark, Q, candidates = frames
    have[1] = 0
    for i in range(candidates.shape[0]):
        flags[i] = 0
        if candidates[i] == 0:
            continue
        c0 = 6 * i + 3
        if have[0] != 0:
            nr = 0
            for j in range(3):
                for k in range(indptr[c0 + j], indptr[c0 + j + 1]):
                    row = indices[k]
                    if row >= c0 and row < c0 + 3:
                        continue  # the node's own rotation block turns on both sides
                    if mark[row] == 0:
                        mark[row] = 1
                        rows[nr] = row
                        nr += 1
                    So[row, j] = prev[k]
                    Sn[row, j] = data[k]
            _turn(Rf, R, i, Q)
            e_body = 0.0
            e_turned = 0.0
            for m in range(nr):
                row = rows[m]
                for j in range(3):
                    turned = So[row, 0] * Q[0, j] + So[row, 1] * Q[1, j] + \
                        So[row, 2] * Q[2, j]
                    e_body += abs(Sn[row, j] - So[row, j])
                    e_turned += abs(Sn[row, j] - turned)
                for j in range(3):
                    So[row, j] = 0.0
                    Sn[row, j] = 0.0
                mark[row] = 0
            if e_turned < TURN_GAIN * e_body:
                flags[i] = 1
                have[1] += 1
        # this factorisation's columns and rotation, for the solves and the next choice
        # (a candidate's only: nothing else is read)
        for k in range(indptr[c0], indptr[c0 + 3]):
            prev[k] = data[k]
        for a in range(3):
            for b in range(3):
                Rf[i, a, b] = R[i, a, b]
    have[0] = 1


@njit(cache=True)
def _turn_entries(v, R, frames, back):
    """Each turned node's rotation entries of ``v`` (neq,) multiplied by ``Q = R_fac^T R``,
    or by ``Q^T`` if ``back``, in place."""
    flags, Rf, have, Q = frames[0], frames[1], frames[3], frames[8]
    if have[1] == 0:
        return
    for i in range(flags.shape[0]):
        if flags[i] == 0:
            continue
        _turn(Rf, R, i, Q)
        c0 = 6 * i + 3
        v0, v1, v2 = v[c0], v[c0 + 1], v[c0 + 2]
        for a in range(3):
            if back:
                v[c0 + a] = Q[0, a] * v0 + Q[1, a] * v1 + Q[2, a] * v2
            else:
                v[c0 + a] = Q[a, 0] * v0 + Q[a, 1] * v1 + Q[a, 2] * v2


@njit(cache=True)
def to_frames(b, R, frames):
    """Right-hand side ``b`` (neq,) into the frames of the factorisation: each turned node's
    rotation entries multiplied by ``Q = R_fac^T R``, in place."""
    _turn_entries(b, R, frames, False)


@njit(cache=True)
def from_frames(d, R, frames):
    """Solution ``d`` (neq,) back from the frames of the factorisation: each turned node's
    rotation entries multiplied by ``Q^T``, in place."""
    _turn_entries(d, R, frames, True)
