"""Rubber bushings between two markers (family ``bushing``): six axes of elastic, damping and
rate-dependent (Maxwell) forces in the bushing frame.

Deflections (measured from the model's initial configuration, where the bushing is unloaded
apart from its preload):

* translation ``d = R_A^T (p_B - p_A) - d0`` [m]: the displacement of marker B's origin
  relative to marker A's origin, in marker A's frame (the *bushing frame*);
* rotation ``theta = log(R_A^T R_B')`` [rad]: the rotation vector of B relative to A, with
  ``R_B' = R_B R_rel0^T`` marker B's frame corrected by its initial orientation relative to A
  (so marker B's own axes do not matter). The logarithm is objective: it does not depend on
  how the pair is oriented in space.

Per axis ``j`` (x, y, z of translation, then of rotation) the law is a Kelvin-Voigt part in
parallel with Maxwell branches::

    f_j = g_j(x_j) + c_j xdot_j + sum_b k_b (x_j - u_b),    c_b u_b' = k_b (x_j - u_b)

with ``g_j`` linear (``k_j x + preload_j``) or a tabulated curve (monotone cubic Hermite,
:mod:`drivedyn.elements.framework.curves`, extrapolated linearly; its value at zero
deflection is a preload, and ``preload_j`` adds to it). Under ``x = X sin(w t)`` the complex
stiffness of an axis is ``K*(w) = k + i w c + sum_b k_b (i w tau_b)/(1 + i w tau_b)``,
``tau_b = c_b/k_b``.

Generalised forces: with ``x = (d, theta)`` and ``xdot = B(q) v`` (``B`` the derivative of
the six deflections with respect to the node coordinates), the residual is ``B^T f``. The
deflections are invariant under any rigid motion of the whole pair, so the forces and
moments on A and B balance exactly, moments about any point included: the force on A is
``+R_A f_d`` acting at marker B's origin (on the line of action of the force ``-R_A f_d`` on
B), and the moments conjugate to ``theta`` are ``T(theta)^-T f_theta`` in B's frame
(``T`` the SO(3) tangent operator; equal to the law's moments for small rotations).

Maxwell branches: the branch spring's deflection ``s_b = x - u_b`` is an internal state
committed at each accepted step, together with the deflections and the time. Between the
committed state (``t_n, x_n, s_n``) and the evaluation (``t, x``) the deflection is taken
linear in time and the branch equation ``s_b' = xdot - s_b / tau_b`` is integrated exactly::

    s_b = phi (x - x_n) + E s_n,    E = exp(-h/tau_b),  phi = (1 - E) tau_b / h,  h = t - t_n

(exact for a piecewise-linear deflection, second order for a smooth one, stable for any
``h/tau_b``); the tangent takes its derivative ``k_b phi``. A static equilibrium at the
committed time (``h = 0``) sees the branches at their committed deflections (they act as
springs of stiffness ``k_b`` on top of the static law).

Energies: potential ``int_0^x g_j + sum_b k_b s_b^2 / 2``, dissipated power
``c_j xdot_j^2 + sum_b k_b^2 s_b^2 / c_b``.

The package, one reason to change per module: :mod:`~drivedyn.elements.bushing.spec`
(:class:`Bushing` and the records of its tables and branches, checked),
:mod:`~drivedyn.elements.bushing.kernel` (deflections, laws, branch update, residual and
tangent) and :mod:`~drivedyn.elements.bushing.family` (the group; importing the package
registers it).
"""

from drivedyn.elements.bushing.family import BushingFamily
from drivedyn.elements.bushing.kernel import OUTPUTS, bushing_kernel
from drivedyn.elements.bushing.spec import (
    AXES,
    Bushing,
    BushingCurve,
    BushingRotationalCurve,
    MaxwellBranch,
    RotationalMaxwellBranch,
)

__all__ = [
    "AXES",
    "OUTPUTS",
    "Bushing",
    "BushingCurve",
    "BushingFamily",
    "BushingRotationalCurve",
    "MaxwellBranch",
    "RotationalMaxwellBranch",
    "bushing_kernel",
]
