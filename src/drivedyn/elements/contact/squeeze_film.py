"""Lubricated annular faces: squeeze film, metal-metal contact and viscous drag (family
``squeeze_film``).

Two parallel annular faces (a gear face and a thrust washer), radii ``r_int < r_ext``, marker A
on one face with its z axis the normal ``n`` towards marker B on the other face. The film
thickness is ``h = (x_B - x_A) . n`` [m] and the force pushing the faces apart is
(physics.md 3; seeds 001, 002; Newtonian, isothermal oil, no wall slip)::

    F_film  = -3 pi mu hdot / (2 h^3) * C,
    C       = r_ext^4 - r_int^4 - (r_ext^2 - r_int^2)^2 / ln(r_ext / r_int)    (annulus)
    C       = r_ext^4                                                       (full disk)
    F_metal = NormalLaw(delta = Ra - h)          below the roughness Ra (metal contact)
    M_drag  = 2 pi (mu omega / h) (r_ext^4 - r_int^4)/4                   viscous drag torque
    M_fr    = mu_R(r_m omega) F_metal r_m                                  metal friction torque

``mu`` [Pa s] is the dynamic viscosity, ``omega`` the relative spin about ``n``. Under a
constant load ``F`` (no metal contact) the faces approach as
``1/h^2 = 1/h0^2 + 4 F t / (3 pi mu C)``.

**Conditioning as h and hdot go to zero** (seed 002's remark). The film force is linear in
``hdot``, so it vanishes smoothly as ``hdot -> 0``; its coefficient ``3 pi mu C / (2 h^3)``
and the drag coefficient ``1/h`` would blow up as ``h -> 0``. Both use an effective
thickness ``h_eff`` instead of ``h``, a C1 blend that never falls below ``h_min``::

    h_eff = h                          for h >= 2 h_min
    h_eff = h_min + h^2 / (4 h_min)    for 0 <= h < 2 h_min
    h_eff = h_min                      for h < 0

so the film damping is bounded by ``3 pi mu C / (2 h_min^3)`` and its derivative is
continuous. The default ``h_min = Ra / 2`` keeps the film law exact wherever there is no metal
contact (``h >= Ra``); below ``Ra`` the metal contact ``K (Ra - h)^n`` carries the load and
keeps ``h`` near ``Ra - (F/K)^(1/n)``, so the film never has to support a load at vanishing
thickness. The film also pulls on separation (negative pressure) unless ``cavitation=True``
clips its force at zero.

Energy: the film power ``-F_film hdot = (3 pi mu C / 2 h_eff^3) hdot^2``, the drag power
``M_drag omega``, the metal contact's damping and friction power are dissipated; the metal
spring's energy is potential energy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.common import (
    add_normal,
    add_velocity_force,
    axial_motion,
    axis_distance,
    check_laws,
    coerce_laws,
    contact_group,
    contact_normal,
    friction_coefficient,
    has_friction,
    omega_projection,
    transpose_times,
    washer_friction_radius,
    washer_work,
    work_size,
)
from drivedyn.elements.contact.friction import FrictionLaw
from drivedyn.elements.contact.impact_laws import NormalLaw, impact_state, initial_state
from drivedyn.elements.framework.building import two_markers, what_of
from drivedyn.elements.framework.checks import check_param, unit_of
from drivedyn.elements.framework.group import Group
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.errors import ModelError


def annulus_factor(r_int: float, r_ext: float) -> float:
    """The bracket C [m^4] of the annular squeeze-film force (``r_ext^4`` for a disk).

    Derived from Reynolds' equation ``(1/r) d/dr (r h^3 dp/dr) = 12 mu hdot`` with ``p = 0``
    at both radii: ``F = -3 pi mu hdot C / (2 h^3)``. For thin annuli the two terms nearly
    cancel (C ~ (r_ext - r_int)^3 r_m): about ``(r_ext/(r_ext - r_int))^2`` of the relative
    accuracy is lost, i.e. still 1e-8 for a width of 1e-4 r_ext.
    """
    if r_int <= 0.0:
        return r_ext**4
    a = r_ext**2 - r_int**2
    return a * (r_ext**2 + r_int**2) - a * a / math.log(r_ext / r_int)


@njit(cache=True, inline="always")
def effective_thickness(h, hmin):
    """h_eff and dh_eff/dh (module docstring)."""
    if h >= 2.0 * hmin:
        return h, 1.0
    if h <= 0.0:
        return hmin, 0.0
    return hmin + h * h / (4.0 * hmin), h / (2.0 * hmin)


@njit(cache=True)
def squeeze_film_kernel(
    pA, pB, RmA, cfilm, cdrag, hmin, rough, cav, rm, area, law, fric, na, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    W = washer_work(work)
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (gn, Hn), (Gs, Ds), vl, Hv, Dv, (dFq, dFv), (ws, wv), M3 = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        o = sc.state_offset(C, e)
        RA = R[nA]
        RB = R[nB]
        sc.velocities(C, e, 12, vl)
        sc.clear(L, full)
        h, hd = axis_distance(x[nA], RA, x[nB], RB, pA[e], pB[e], RmA[e, :, 2], gn, Hn, vl, Hv,
                              full, ws, wv)
        # film: F_f = -c(h) hdot, c = cfilm / h_eff^3
        he, dhe = effective_thickness(h, hmin[e])
        cf = cfilm[e] / (he * he * he)
        Ff = -cf * hd
        dFf_h = 3.0 * cf * dhe / he * hd
        dFf_hd = -cf
        if cav[e] and Ff < 0.0:
            Ff = 0.0
            dFf_h = 0.0
            dFf_hd = 0.0
        # metal contact on delta = Ra - h
        delta = rough[e] - h
        rate = -hd
        Fm, Fmd, Fmr, V, Pm, vs = contact_normal(law, e, delta, rate, es, o)
        # total force pushing the faces apart, as a function of delta = Ra - h
        # (d/ddelta = -d/dh, d/ddeltadot = -d/dhdot)
        add_normal(Fm + Ff, Fmd - dFf_h, Fmr - dFf_hd, -1.0, gn, Hn, Hv, rq, K, Cd, dFq, dFv,
                   full)
        if full:
            # the metal friction torque depends on the metal force alone
            for b in range(12):
                dFq[b] = -(Fmd * gn[b] + Fmr * Hv[b])
                dFv[b] = -Fmr * gn[b]
        omega_projection(RA, RB, RmA[e, :, 2], Gs, Ds, full, M3)
        w = 0.0
        for a in range(12):
            w += Gs[a] * vl[a]
        if full:
            transpose_times(Ds, vl, Dv)
        # viscous drag M_v = (cdrag / h_eff) w, a function of h (via gn) and w
        cd = cdrag[e] / he
        Mv = cd * w
        dMv_h = -cd * dhe / he * w
        for a in range(12):
            rq[a] += Mv * Gs[a]
        if full:
            for a in range(12):
                ga = Gs[a]
                for b in range(12):
                    K[a, b] += Mv * Ds[a, b] + ga * (cd * Dv[b] + dMv_h * gn[b])
                    Cd[a, b] += ga * cd * Gs[b]
        Mf = 0.0
        mu_now = 0.0
        if Fm > 0.0 and has_friction(fric, e):
            mu_now, dmu = friction_coefficient(fric, e, rm[e] * w)
            Mf = mu_now * Fm * rm[e]
            add_velocity_force(Mf, dmu * Fm * rm[e] * rm[e], mu_now * rm[e], Gs, Ds, Dv, dFq,
                               dFv, rq, K, Cd, full)
        pdis = -Ff * hd + Pm + Mv * w + Mf * w
        sc.report(C, e, (Ff + Fm, Ff, Fm, h, hd, (Ff + Fm) / area[e], w, Mv, Mf, pdis))
        sc.energy(C, e, 0.0, V, 0.0, pdis)
        impact_state(delta, rate, vs, t, es, o, aux, e, na)
        sc.scatter(C, L, e, 2, full)


@dataclass(frozen=True)
class SqueezeFilm(TwoMarkerSpec):
    """Oil film between two annular faces, with metal contact below the roughness.

    Attributes:
        name: unique element name.
        marker_a: face A: origin on the face, z axis = normal towards face B.
        marker_b: face B (origin on it, on the axis).
        viscosity: dynamic viscosity mu [Pa s] > 0 (gear oil at 80 C: about 0.01-0.02).
        r_int, r_ext: radii of the annulus [m], 0 <= r_int < r_ext (r_int = 0: full disk).
        roughness: Ra [m] >= 0; metal contact below h = Ra.
        contact: normal law of the metal contact on ``delta = Ra - h``.
        friction: friction law of the metal contact (torque on the relative spin), or None.
        min_film: h_min [m] > 0 of the conditioning blend; None = Ra / 2.
        cavitation: clip the film force at zero (no film tension on separation).
    """

    viscosity: float = 0.0
    r_int: float = 0.0
    r_ext: float = 0.0
    roughness: float = 0.0
    contact: NormalLaw = field(default_factory=lambda: NormalLaw(1e10, 1.0, law="penalty"))
    friction: FrictionLaw | None = None
    min_film: float | None = None
    cavitation: bool = False
    family: ClassVar[str] = "squeeze_film"
    units: ClassVar[dict[str, str]] = {
        "viscosity": "Pa s",
        "r_int": "m",
        "r_ext": "m",
        "roughness": "m",
        "min_film": "m",
    }

    def __post_init__(self) -> None:
        coerce_laws(self, what_of(self), "contact")

    @property
    def law(self) -> NormalLaw:
        return self.contact

    @property
    def h_min(self) -> float:
        """The effective h_min [m]."""
        return float(self.min_film) if self.min_film is not None else 0.5 * self.roughness

    def validate(self) -> None:
        what = what_of(self)
        check_param(self, "viscosity", 0.0, strict=True)
        ri = check_param(self, "r_int", 0.0)
        re = check_param(self, "r_ext", 0.0, strict=True)
        if ri >= re:
            m = unit_of(self, "r_ext")
            raise ModelError(f"{what}: r_int = {self.r_int!r} {m} must be < r_ext = "
                             f"{self.r_ext!r} {m}")
        check_param(self, "roughness", 0.0)
        if self.min_film is not None:
            check_param(self, "min_film", 0.0, strict=True)
        elif self.roughness == 0.0:
            raise ModelError(f"{what}.min_film: needed (> 0) when roughness is 0 (the film "
                             "force is regularised below h_min)")
        check_laws(self, what)

    @property
    def film_factor(self) -> float:
        """3 pi C / 2 [m^4]: the film force is -film_factor mu hdot / h^3."""
        return 1.5 * math.pi * annulus_factor(self.r_int, self.r_ext)


class SqueezeFilmFamily(Family):
    """Registry entry of :class:`SqueezeFilm`."""

    name = "squeeze_film"

    def build(self, specs, ctx) -> Group:
        pA, pB, RmA, _, lnodes = two_markers(specs, ctx, "a contact")
        states = []
        for e, s in enumerate(specs):
            h, hd = axial_motion(ctx, lnodes[e, 0], pA[e], RmA[e][:, 2], lnodes[e, 1], pB[e])
            states.append(initial_state(s.roughness - h, -hd, s.contact.min_impact_speed))

        def arr(f):
            return np.array([float(f(s)) for s in specs], float)

        geom = (
            pA, pB, RmA,
            arr(lambda s: s.viscosity * s.film_factor),
            arr(lambda s: 0.5 * math.pi * s.viscosity * (s.r_ext**4 - s.r_int**4)),
            arr(lambda s: s.h_min),
            arr(lambda s: s.roughness),
            np.array([bool(s.cavitation) for s in specs], np.bool_),
            arr(lambda s: washer_friction_radius(s.r_int, s.r_ext)),
            arr(lambda s: math.pi * (s.r_ext**2 - s.r_int**2)),
        )
        outputs = (
            ("normal_force", "N", "total force pushing the faces apart (film + metal)"),
            ("film_force", "N", "squeeze-film force"),
            ("contact_force", "N", "metal-metal contact force (below the roughness)"),
            ("film_thickness", "m", "distance h of the faces along the normal of face A"),
            ("film_rate", "m/s", "dh/dt (< 0: approaching)"),
            ("pressure", "Pa", "mean pressure (film + metal) over the face area"),
            ("relative_spin", "rad/s", "spin of B relative to A about the normal"),
            ("drag_torque", "N m", "viscous drag torque of the film resisting the spin"),
            ("friction_torque", "N m", "metal friction torque resisting the spin"),
            ("dissipated_power", "W", "film + drag + metal contact and friction power"),
        )
        return contact_group(self.name, specs, ctx, squeeze_film_kernel, geom, states, outputs,
                             lnodes, work_size.py_func(2, 5))


register(SqueezeFilmFamily())
