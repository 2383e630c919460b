"""Oil film in the clearance of a pin in a bore: squeeze-film damping (family
``journal_film``).

:class:`JournalFilm`: a pin (marker B, its origin the pin centre) in a bore (marker A, z = bore
axis), radial clearance ``c = bore_radius - pin_radius`` [m], the pin centre's offset ``e``
from the bore axis (normal to ``z_A``), eccentricity ``eps = |e| / c``. The film is the
short-length squeeze-film damper (Reynolds' equation with the axial pressure flow only,
uncavitated over the whole circumference; Vance, *Rotordynamics of Turbomachinery*, 1988,
ch. 6; San Andres, *Squeeze Film Dampers*, Texas A&M notes): a radial velocity ``edot_r`` and
a whirl velocity ``e thetadot`` of the pin centre meet the forces on the pin::

    F_r = -C_rr edot_r,  F_t = -C_tt e thetadot,
    C_tt = C0 / (1 - eps^2)^(3/2),   C_rr = C0 (1 + 2 eps^2) / (1 - eps^2)^(5/2),

with, for a plain journal of radius ``R = pin_radius`` and film length ``L``::

    C0 = pi mu R L^3 / c^3                                   (lands = 0)

and, for a pin whose film is cut into ``n`` axial lands of width ``b`` (gear tips in a
pocket: the oil escapes sideways into the tooth spaces, each land a narrow pad of length ``L``
squeezing over its width, ``F = mu L b^3 (-hdot) / h^3``; the sum over lands spread evenly
round the pin gives the same eccentricity functions)::

    C0 = n mu L b^3 / (2 c^3)                                (lands = n)

``mu`` [Pa s] is the oil's dynamic viscosity. The film carries no load at rest and dissipates
``C_rr edot_r^2 + C_tt (e thetadot)^2``. The pin's spin makes no force here (the wedge of a
hydrodynamic journal bearing needs a continuous film; on gear tips the lands interrupt it).

Near the wall and in metal contact (a :class:`~drivedyn.elements.contact.JournalContact` on
the same markers, whose "penetration" is the elastic approach of the surfaces) the film sees
the pin at radius ``rho = c - h_eff`` instead of ``|e|``, with ``h = c - |e|`` the film
thickness at the closest point and ``h_eff`` the C1 blend of
:func:`~drivedyn.elements.contact.squeeze_film.effective_thickness` that never falls below
``min_film`` (``eps_f = rho / c = 1 - h_eff / c``): the film's pin moves radially at
``h_eff'(h) edot_r`` (none in metal contact: an elastic approach squeezes no oil, the
asperities carry the load) and along the wall at ``(rho / |e|) e thetadot``. The forces on
the pin are ``-C_rr(eps_f) h_eff' . (h_eff' edot_r)`` and ``-C_tt(eps_f) (rho/|e|)^2 e
thetadot``: bounded, and equal to the formulas above wherever ``h >= 2 min_film``.

Formulation: with ``p1, p2`` the pin centre's offset along the bore's x and y axes (gradients
``g1, g2``, rates ``s_i = g_i . v``), ``pg = p1 g1 + p2 g2`` and ``w = pg . v`` (``= |e|
edot_r``), the generalised force is ``a (s1 g1 + s2 g2) + b w pg`` with ``a = C_tt
(rho/|e|)^2`` and ``b = (C_rr h_eff'^2 - a) / |e|^2``; clear of the wall ``b = 3 C0 / (c^2
(1 - eps^2)^(5/2))``, smooth at the centred position, where the film is isotropic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

import drivedyn.elements.framework.scaffold as sc
from drivedyn.elements.contact.common import transpose_times, work_offsets, work_size
from drivedyn.elements.contact.squeeze_film import effective_thickness
from drivedyn.elements.framework.building import make_group, node_dofs, two_markers, what_of
from drivedyn.elements.framework.checks import check_param, unit_of
from drivedyn.elements.framework.contract import local_arrays_at
from drivedyn.elements.framework.primitives import prim_axial
from drivedyn.elements.framework.registry import Family, TwoMarkerSpec, register
from drivedyn.elements.framework.work_arrays import carve
from drivedyn.errors import ModelError

#: work buffer: three gradient/Hessian pairs, four vectors of 12
_WORK = work_size.py_func(3, 4)  # the plain function: nothing compiled at import


@njit(cache=True, inline="always")
def _blend_curvature(h, hmin):
    """d2 h_eff / dh2 of :func:`effective_thickness`."""
    return 1.0 / (2.0 * hmin) if 0.0 < h < 2.0 * hmin else 0.0


@njit(cache=True)
def journal_film_kernel(
    pA, pB, RmA, clear, c0, hmin, work,
    lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn,
    cM, cC, cK, mode, want, r, rabs, data, eout, aux,
):
    buf = sc.work_buffer(work, _WORK)
    G, V, w = work_offsets(3, 4)
    W = (local_arrays_at(buf, 0, 12, 0), sc.grad_hess_at(buf, G, 12),
         sc.grad_hess_at(buf, G + 156, 12), sc.grad_hess_at(buf, G + 312, 12),
         carve(buf, V, 12), carve(buf, V + 12, 12), carve(buf, V + 24, 12),
         carve(buf, V + 36, 12), sc.workspace_at(buf, w))
    C = (lnodes, dofs, kmap, eoff, x, R, v, vd, lam, es, tfv, t, Tn, cM, cC, cK, mode, want,
         r, rabs, data, eout, aux)
    L, (g1, H1), (g2, H2), (gp, Hp), vl, Hv1, Hv2, Hvp, (ws, wv) = W
    full = sc.full_pass(want, mode)
    rq, _, _, Cd, K, _ = L
    for e in range(sc.count(C)):
        nA, nB = sc.pair(C, e)
        sc.velocities(C, e, 12, vl)
        sc.clear(L, full)
        p1 = prim_axial(x[nA], R[nA], x[nB], R[nB], pA[e], pB[e], RmA[e, :, 0], g1, H1, full,
                        ws, wv)
        p2 = prim_axial(x[nA], R[nA], x[nB], R[nB], pA[e], pB[e], RmA[e, :, 1], g2, H2, full,
                        ws, wv)
        c = clear[e]
        k0 = c0[e]
        roff = math.sqrt(p1 * p1 + p2 * p2)
        h = c - roff
        he, dhe = effective_thickness(h, hmin[e])
        eps = 1.0 - he / c
        A = (he / c) * (2.0 - he / c)  # 1 - eps_f^2
        Ct = k0 / (A * math.sqrt(A))
        Crr = k0 * (1.0 + 2.0 * eps * eps) / (A * A * math.sqrt(A))
        s1 = 0.0
        s2 = 0.0
        for a in range(12):
            gp[a] = p1 * g1[a] + p2 * g2[a]
            s1 += g1[a] * vl[a]
            s2 += g2[a] * vl[a]
        w = p1 * s1 + p2 * s2
        # force a (s1 g1 + s2 g2) + b w pg; a' = ka roff, b' = kb roff (d/droff)
        if h >= 2.0 * hmin[e]:
            # the film's pin is the pin: a = C_tt, b = (C_rr - C_tt) / |e|^2 (smooth at 0)
            a_ = Ct
            b_ = 3.0 * k0 / (c * c * A * A * math.sqrt(A))
            kA = -2.0 / (c * c)
            ka = -1.5 * Ct / A * kA
            kb = -2.5 * b_ / A * kA
        else:
            # the film's pin at radius c - h_eff: s = eps c / |e|, radial rate x h_eff'
            dd = _blend_curvature(h, hmin[e])
            sr = eps * c / roff
            a_ = Ct * sr * sr
            b_ = (Crr * dhe * dhe - a_) / (roff * roff)
            dA = -2.0 / c * eps * dhe
            dCt = -1.5 * Ct / A * dA
            deps = dhe / c
            dCrr = k0 * (4.0 * eps * deps / (A * A * math.sqrt(A))
                         - 2.5 * (1.0 + 2.0 * eps * eps) / (A * A * A * math.sqrt(A)) * dA)
            dsr = (dhe * roff - eps * c) / (roff * roff)
            da = dCt * sr * sr + 2.0 * Ct * sr * dsr
            db = ((dCrr * dhe * dhe - 2.0 * Crr * dhe * dd - da) / (roff * roff)
                  - 2.0 * b_ / roff)
            ka = da / roff
            kb = db / roff
        f1 = a_ * s1
        f2 = a_ * s2
        f3 = b_ * w
        for a in range(12):
            rq[a] += f1 * g1[a] + f2 * g2[a] + f3 * gp[a]
        if full:
            transpose_times(H1, vl, Hv1)
            transpose_times(H2, vl, Hv2)
            for a in range(12):
                for b in range(12):
                    Hp[a, b] = g1[a] * g1[b] + p1 * H1[a, b] + g2[a] * g2[b] + p2 * H2[a, b]
            transpose_times(Hp, vl, Hvp)
            for a in range(12):
                ga1 = g1[a]
                ga2 = g2[a]
                gpa = gp[a]
                for b in range(12):
                    K[a, b] += (f1 * H1[a, b] + f2 * H2[a, b] + f3 * Hp[a, b]
                                + ga1 * (a_ * Hv1[b] + s1 * ka * gp[b])
                                + ga2 * (a_ * Hv2[b] + s2 * ka * gp[b])
                                + gpa * (b_ * Hvp[b] + w * kb * gp[b]))
                    Cd[a, b] += a_ * (ga1 * g1[b] + ga2 * g2[b]) + b_ * gpa * gp[b]
        # film forces on the pin: radial -C_rr h_eff' edot_r, tangential -C_tt s e thetadot
        fr = 0.0
        ft = 0.0
        if roff > 0.0:
            fr = -Crr * dhe * w / roff
            ft = -Ct * (eps * c / roff) * (p1 * s2 - p2 * s1) / roff
        pdis = f1 * s1 + f2 * s2 + f3 * w
        sc.report(C, e, (fr, ft, roff / c, h, Crr, Ct, pdis))
        sc.energy(C, e, 0.0, 0.0, 0.0, pdis)
        sc.scatter(C, L, e, 2, full)


@dataclass(frozen=True)
class JournalFilm(TwoMarkerSpec):
    """Squeeze film of oil in the clearance of a pin (``marker_b``, its origin the pin
    centre) in a bore (``marker_a``, z = bore axis); module docstring.

    Attributes:
        name: unique element name.
        marker_a: bore: origin on the bore axis, z axis along it.
        marker_b: pin centre (in the middle of the film length).
        viscosity: dynamic viscosity mu [Pa s] > 0.
        length: axial length L [m] > 0 of the film.
        bore_radius: [m] > pin_radius.
        pin_radius: R [m] > 0 (for gear tips: the tip radius).
        lands: 0 for a plain journal; n > 0 for a film cut into n axial lands (gear tips).
        land_width: width b [m] of each land (lands > 0), n b <= 2 pi R.
        min_film: h_min [m] of the blend near contact, 0 < h_min < (bore - pin radius) / 2
            (the surfaces' roughness: closer than that, asperities carry the load).
    """

    viscosity: float = 0.0
    length: float = 0.0
    bore_radius: float = 0.0
    pin_radius: float = 0.0
    lands: int = 0
    land_width: float = 0.0
    min_film: float = 0.0
    family: ClassVar[str] = "journal_film"
    units: ClassVar[dict[str, str]] = {"viscosity": "Pa s", "length": "m", "bore_radius": "m",
                                       "pin_radius": "m", "land_width": "m",
                                       "min_film": "m"}  # lands: a count

    @property
    def clearance(self) -> float:
        """Radial clearance c [m]."""
        return self.bore_radius - self.pin_radius

    @property
    def centred_damping(self) -> float:
        """C0 [N s/m]: the film's damping coefficient at the centred position."""
        c3 = self.clearance**3
        if self.lands == 0:
            return math.pi * self.viscosity * self.pin_radius * self.length**3 / c3
        return self.lands * self.viscosity * self.length * self.land_width**3 / (2.0 * c3)

    def validate(self) -> None:
        what = what_of(self)
        check_param(self, "viscosity", 0.0, strict=True)
        check_param(self, "length", 0.0, strict=True)
        rb = check_param(self, "bore_radius", 0.0, strict=True)
        rp = check_param(self, "pin_radius", 0.0, strict=True)
        if rp >= rb:
            m = unit_of(self, "bore_radius")
            raise ModelError(f"{what}: pin_radius = {self.pin_radius!r} {m} must be < "
                             f"bore_radius = {self.bore_radius!r} {m} (the film needs a "
                             f"clearance)")
        if isinstance(self.lands, bool) or not isinstance(self.lands, (int, np.integer)) \
                or self.lands < 0:
            raise ModelError(f"{what}.lands: expected an integer >= 0 (0: plain journal), got "
                             f"{self.lands!r}")
        if self.lands > 0:
            b = check_param(self, "land_width", 0.0, strict=True)
            if self.lands * b > 2.0 * math.pi * rp:
                m = unit_of(self, "land_width")
                raise ModelError(f"{what}.land_width: {self.lands} lands of {b!r} {m} do not "
                                 f"fit round a pin of radius {rp!r} {m} (n b <= 2 pi R "
                                 f"expected)")
        hm = check_param(self, "min_film", 0.0, strict=True)
        if hm >= 0.5 * (rb - rp):
            m = unit_of(self, "min_film")
            raise ModelError(f"{what}.min_film: {self.min_film!r} {m} must be below half the "
                             f"radial clearance ({0.5 * (rb - rp)!r} {m})")


class JournalFilmFamily(Family):
    """Registry entry of :class:`JournalFilm`."""

    name = "journal_film"

    def build(self, specs, ctx):
        pA, pB, RmA, _, lnodes = two_markers(specs, ctx, "a journal film")
        params = (
            pA, pB, RmA,
            np.array([s.clearance for s in specs], float),
            np.array([s.centred_damping for s in specs], float),
            np.array([s.min_film for s in specs], float),
            np.zeros(_WORK),
        )
        outputs = (
            ("radial_force", "N", "film force on the pin along the offset from the bore axis "
             "(< 0: resists an approach to the wall)"),
            ("tangential_force", "N", "film force on the pin normal to the offset (resists "
             "the whirl)"),
            ("eccentricity", "1", "offset of the pin centre / radial clearance"),
            ("film_thickness", "m", "smallest film thickness c - |e| (< 0: metal contact)"),
            ("radial_damping", "N s/m", "C_rr at the current eccentricity"),
            ("tangential_damping", "N s/m", "C_tt at the current eccentricity"),
            ("dissipated_power", "W", "power dissipated in the film"),
        )
        return make_group(self.name, specs, journal_film_kernel, params, lnodes,
                          node_dofs(ctx, lnodes), outputs, dissipative=True)


register(JournalFilmFamily())
