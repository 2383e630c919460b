"""Gear pair: a compliant 3-D tooth mesh between two wheels (family ``gear_pair``).

The element joins two markers at the wheel centres (each marker's z axis is the wheel axis)
and acts as a nonlinear spring-damper along the tooth normal at the pitch point, after
Cardona's gear element (seed 003, "Gear pair element"; ``physics.md`` section 2), in the
equivalent compliant form the design allows: the mesh deflection is a function of the
configuration of the two wheels, measured from wheel rotations relative to the mesh frame
(accumulated over any number of revolutions) and the relative displacement of the wheels.

Mesh coordinates ``s`` (functions of the two node configurations, with exact gradients and
right-trivialised Hessians from :mod:`drivedyn.elements.framework.primitives`):

* ``phi_A, phi_B``: rotation of each wheel about its own axis relative to the mesh frame
  (accumulated in ``State.es``). Parallel axes: relative to the centre line, i.e. the
  projection of ``d = x_mB - x_mA`` onto the wheel's plane. Bevel and crossed axes: relative
  to the other wheel's axis projected onto the wheel's plane. Both references turn with a
  carrier, so a planetary set obeys the Willis equation without anything special.
* ``delta = (d.a, d.f_r, d.f_t)``: the centre offset in the mesh frame ``(a, f_r, f_t)``
  (``f_r`` towards the other wheel). Parallel axes use ``(d.a, a_c, 0)`` with the transverse
  centre distance ``a_c = |d - (d.a) a|``.

Flank approach (penetration along the tooth normal ``n``, in m; ``u > 0`` = contact)::

    x   = c_A (phi_A - phi_A0) + c_B (phi_B - phi_B0) + cx . (delta - delta0)
          + X (1 - cos(z_A (phi_A - phi_A0))) - g0                (odd under flank mirror)
    rho = cr . (delta - delta0)                                     bevel, crossed axes
    rho = -/+ cos(beta_b) R [inv alpha_wt(a_c) - inv alpha_wt(a_c0)]  parallel, ext./int.
    u_drive = x + rho,     u_coast = -x + rho - b_n

``c_A = r_bA cos(beta_b)`` etc. come from the tooth normal at the pitch point; the exact
involute term (``cos alpha_wt = R / a_c``, ``R = r_bA +/- r_bB``) makes the radial force
follow the operating pressure angle when the centre distance changes; the axial offset enters
with ``sin(beta_b)`` exactly (involute helicoids). ``b_n`` is the normal backlash and ``g0``
the initial drive-flank gap. Each flank is a unilateral spring-damper::

    F = k_m(phi_A) u + c_m du/dt   while u > 0 (contact), else 0

with the potential ``V = k_m u^2 / 2`` per flank (the seeds' ``k_m [[u + x_err]]^2 / 2``
with the hoop backlash operator ``[[.]]`` when the centre distance is nominal). The
generalised force is ``F du/dq`` plus, for a stiffness that varies over the mesh cycle,
``V'(phi_A)`` (a conservative formulation: the energy balance closes exactly). The damper
acts on the rate of the whole flank deflection (transmission error included) and only in
contact; it is not clipped, so at separation it may briefly pull (Kelvin-Voigt contact).
The varying stiffness is ``k' (0.75 n + 0.25)`` with ``n`` tooth pairs in contact (n and
n + 1 over the fractions set by ``eps_alpha``; its cycle mean is ISO's
``c' (0.75 eps_alpha + 0.25)``), with quintic-smoothed steps; the mesh phase is
``z_A (phi_A - phi_A0) / 2 pi``.

Tooth friction (regularised Coulomb law of the seeds, ``physics.md`` section 3) acts on the
sliding velocity vector ``v_s = W s_dot`` (2 components, m/s): sliding at the pitch point
along the tooth trace (crossed axes, worms, and any relative axial motion of helical
gears), and the profile sliding of parallel and bevel gears at the effective contact
distance ``s_eff`` from the pitch point (mean loss of the ISO/TR 14179-2 gear loss factor,
see :func:`~drivedyn.elements.gears.geometry.effective_sliding_arm`)::

    Q_fric = mu_R(|v_s|) / |v_s| F_N  W^T v_s,    F_N = |F_drive| + |F_coast|

Its power ``mu_R(|v_s|) F_N |v_s|`` is reported as dissipated power, like the damping power.
The profile-sliding part is a couple on the two wheels (it changes the torque ratio, i.e.
the efficiency, not the mesh force); the trace part acts at the pitch point.

Sign conventions: the *drive flank* is the one that wheel A loads when it turns positively
about its axis (marker A's z); forces are reported on wheel B, in the global frame and in the
gear frame of wheel A at the pitch point: tangential ``t = a x e`` (direction of A's surface
motion), radial ``e`` (from A's axis towards the pitch point; positive radial force
separates the wheels) and axial ``a``; with these, a parallel pair gives
``F_a = -F_t tan(beta_A)``, ``F_r = |F_t| tan(alpha_n) / cos(beta)``. Helix (spiral) angles
are positive for a right hand (the tooth trace ``cos(beta) a + sin(beta) t`` turns
positively about the axis as it advances along it); external parallel pairs need opposite
hands, internal pairs the same. ``torque_a``/``torque_b`` are the mesh torques on the wheels
about their own axes (friction included).

Numerics: ``flank_onset = d`` (default 0) makes a flank's elastic force rise smoothly over
its first ``d`` of approach (``k u^2 / (2 d)``, then ``k (u - d/2)``, from a potential), so
that a flank closing within a step does not make Newton diverge (zero-torque holds of the
TORSEN vehicle configuration: 134 failures in 0.3 s without it, none with 20 nm).
Contact status changes the iteration matrix, so a flank within ``TANGENT_BAND``
(1 pm) of contact while neither flank is loaded lends its stiffness to the matrix (not to
the residual): a zero-backlash mesh that is unloaded when the matrix is factorised (at
t = 0, say) would otherwise enter it with no stiffness. The band is kept at round-off size:
with 10 nm, planets floating a few nanometres off the sun at zero torque keep the lent
stiffness in a matrix whose residual has none, and Newton converges only linearly (a
zero-torque hold costs minutes per simulated second). The code that only bevel and
crossed pairs need and the assembly of the matrices are compiled out of line (first
compilation ~70 s instead of ~2 min), and the residual-only loop over parallel pairs is a
separate copy with the kind a compile-time constant (fixed loop lengths: 1.5x faster).

What is simplified (documented limits): one mean contact point (no line-contact
distribution over the face width, so misalignment changes the load but not its distribution);
bevel gears use the mean point of the pitch cones with linearised displacements and ISO 6336
stiffness of their virtual cylindrical gears; crossed-axis helical and worm pairs are point
contacts at the pitch point with sliding along the common tooth trace only, and need an
explicit stiffness (ISO 6336 does not cover them).

The package, one reason to change per module: :mod:`~drivedyn.elements.gears.geometry`
(involute geometry), :mod:`~drivedyn.elements.gears.stiffness` (ISO 6336 mesh stiffness and
its variation over the mesh cycle), :mod:`~drivedyn.elements.gears.kinematics` (mesh
coordinates and the chain rule), :mod:`~drivedyn.elements.gears.kernel` (mesh law, friction,
outputs), :mod:`~drivedyn.elements.gears.spec` (:class:`GearPair`),
:mod:`~drivedyn.elements.gears.mesh` (mesh frame and law coefficients at build time) and
:mod:`~drivedyn.elements.gears.family` (the group; importing the package registers it).
"""

from drivedyn.elements.gears.family import GearPairFamily, mesh_info
from drivedyn.elements.gears.geometry import (
    CylindricalPair,
    base_helix_angle,
    effective_sliding_arm,
    inverse_involute,
    involute,
    transverse_pressure_angle,
    undercut_limits,
)
from drivedyn.elements.gears.kernel import GEAR_AUX, gear_kernel
from drivedyn.elements.gears.spec import KINDS, GearPair
from drivedyn.elements.gears.stiffness import (
    E_STEEL,
    IsoStiffness,
    iso6336_mesh_stiffness,
    iso6336_single_stiffness,
    mesh_cycle_levels,
)

__all__ = [
    "E_STEEL",
    "GEAR_AUX",
    "KINDS",
    "CylindricalPair",
    "GearPair",
    "GearPairFamily",
    "IsoStiffness",
    "base_helix_angle",
    "effective_sliding_arm",
    "gear_kernel",
    "inverse_involute",
    "involute",
    "iso6336_mesh_stiffness",
    "iso6336_single_stiffness",
    "mesh_cycle_levels",
    "mesh_info",
    "transverse_pressure_angle",
    "undercut_limits",
]
