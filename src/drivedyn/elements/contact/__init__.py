"""Contact elements and their laws. Importing this package registers every contact family.

* :mod:`~drivedyn.elements.contact.plane`: :class:`PlaneContact`, a point or sphere on a plane
  (family ``plane_contact``).
* :mod:`~drivedyn.elements.contact.thrust_washer`: :class:`ThrustWasherContact`, an annular
  face on a thrust washer (``thrust_washer_contact``).
* :mod:`~drivedyn.elements.contact.journal`: :class:`JournalContact`, a pin in a bore
  (``journal_contact``).
* :mod:`~drivedyn.elements.contact.journal_film`: :class:`JournalFilm`, the oil film of a pin
  in a bore (squeeze-film damping, ``journal_film``).
* :mod:`~drivedyn.elements.contact.squeeze_film`: :class:`SqueezeFilm`, lubricated annular
  faces (``squeeze_film``).
* :mod:`~drivedyn.elements.contact.unilateral`: :class:`UnilateralContact`, stick/slip
  contact by augmented Lagrangian (``unilateral_contact``).
* :mod:`~drivedyn.elements.contact.impact_laws`: :class:`NormalLaw`, penalty and
  continuous-impact normal force laws, and the per-contact impact state.
* :mod:`~drivedyn.elements.contact.friction`: :class:`FrictionLaw`, regularised Coulomb
  friction (also used by :class:`~drivedyn.elements.flexible.FlexibleWasherContact`).
* :mod:`~drivedyn.elements.contact.common`: what the force-type contact kernels and their
  groups share.

**Force-type contacts** (plane, thrust washer, journal). Every contact computes a penetration
``delta`` [m] from the marker frames, a normal force from a :class:`NormalLaw` (penalty or
continuous impact, with the approach speed at first contact kept in the State) and a friction
force or torque from a :class:`FrictionLaw`. It reports its normal force, gap, sliding
velocity, friction force or torque and dissipated power, puts the contact spring's potential
energy into the energy account and counts the impact damping and friction power as
dissipated (physics.md 3, seeds 000-002). Markers on the ground are allowed on either side.

Formulation: the residual is a sum of scalar forces times gradients of kinematic functions
(:mod:`drivedyn.elements.framework.primitives`): ``delta`` (distance along a marker axis, or
the norm of two of them for the journal) and velocity-level sliding rates ``s = J(q) . v``,
for which ``J`` and ``dJ/dq`` are known (relative spin projected on a marker axis,
:func:`~drivedyn.elements.contact.common.omega_projection`). The stiffness is
``F d2delta/dq2 + grad(delta) (dF/dq)^T`` plus the friction terms ``f dJ/dq + J (df/dq)^T``,
the damping ``grad(delta) (dF/dv)^T + J (df/dv)^T``; both are non-symmetric, as the Newton
matrix allows.

Per-contact state (:data:`~drivedyn.elements.contact.impact_laws.NSTATE` floats in
``State.es``): contact flag, approach speed at first contact, last penetration, rate, time
and acceleration, last separation speed, number of contacts; the kernel writes the values of
an accepted step into hidden ``aux`` columns and the group's ``commit`` copies them (never
during Newton iterations).

Laws may be given as mappings (model files: TOML tables), e.g.
``law = {stiffness = 1e10, exponent = 1.5, law = "lankarani-nikravesh", restitution = 0.8}``.
"""

from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw
from drivedyn.elements.contact.journal import JournalContact
from drivedyn.elements.contact.journal_film import JournalFilm
from drivedyn.elements.contact.plane import PlaneContact
from drivedyn.elements.contact.squeeze_film import SqueezeFilm
from drivedyn.elements.contact.thrust_washer import ThrustWasherContact
from drivedyn.elements.contact.unilateral import UnilateralContact

__all__ = ["FrictionLaw", "JournalContact", "JournalFilm", "NormalLaw", "PlaneContact",
           "SqueezeFilm", "ThrustWasherContact", "UnilateralContact"]
