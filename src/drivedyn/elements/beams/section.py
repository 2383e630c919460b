"""Beam materials and cross-sections, and the stresses on the outer fibre of a section.

The section frame has x along the beam axis and y, z along the principal axes of the
section. Section forces are ``(N, V_y, V_z, T, M_y, M_z)`` [N, N m]; a positive ``M_y``
stretches the fibres at ``z > 0`` and a positive ``M_z`` those at ``y < 0``::

    sigma_x(y, z) = N / A + M_y z / I_y - M_z y / I_z

Shear areas use Cowper's (1966) coefficients; torsion is Saint-Venant's (no warping
restraint; Bredt's thin-walled formula for the box). Every value is SI: m, Pa, kg/m^3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numba import njit

from drivedyn.elements.framework.checks import unit_of
from drivedyn.errors import ModelError

KIND_CIRCULAR = 0
KIND_RECTANGULAR = 1
KIND_GENERAL = 2
KIND_BOX = 3

_NPTS = 32  # points sampled on the outer circle
_COS = np.cos(2.0 * np.pi * np.arange(_NPTS) / _NPTS)  # tables: the kernels call the stress
_SIN = np.sin(2.0 * np.pi * np.arange(_NPTS) / _NPTS)  # recovery at every evaluation


def _positive(what: str, value: float, unit: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: expected a number [{unit}], got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise ModelError(f"{what}: must be > 0 {unit}, got {value!r}")
    return v


@dataclass(frozen=True)
class Material:
    """Linear elastic isotropic material.

    Attributes:
        E: Young's modulus [Pa]. G: shear modulus [Pa]. density: [kg/m^3].
    """

    E: float
    G: float
    density: float
    units: ClassVar[dict[str, str]] = {"E": "Pa", "G": "Pa", "density": "kg/m^3"}

    def __post_init__(self) -> None:
        for label in ("E", "G", "density"):
            object.__setattr__(self, label, _positive(f"material.{label}",
                                                      getattr(self, label),
                                                      unit_of(Material, label)))
        nu = self.nu
        if not -1.0 < nu < 0.5:
            raise ModelError(f"material: Poisson's ratio E/(2G) - 1 = {nu:.4g} (E = {self.E:g}"
                             f" Pa, G = {self.G:g} Pa) must lie in (-1, 0.5)")

    @classmethod
    def from_nu(cls, E: float, nu: float, density: float) -> Material:
        """Material from Young's modulus [Pa], Poisson's ratio and density [kg/m^3]."""
        try:
            n = float(nu)
        except (TypeError, ValueError):
            raise ModelError(f"material.nu: expected a number, got {nu!r}") from None
        if not -1.0 < n < 0.5:
            raise ModelError(f"material.nu: must lie in (-1, 0.5), got {nu!r}")
        E = _positive("material.E", E, unit_of(cls, "E"))
        return cls(E, E / (2.0 * (1.0 + n)), density)

    @property
    def nu(self) -> float:
        """Poisson's ratio ``E / (2 G) - 1``."""
        return self.E / (2.0 * self.G) - 1.0


STEEL = Material.from_nu(210e9, 0.3, 7850.0)
"""Steel: E = 210 GPa, nu = 0.3, density 7850 kg/m^3."""


@dataclass(frozen=True)
class SectionProperties:
    """What the beam element needs from a section and its material.

    Attributes:
        stiffness: (6,) ``[EA, GA_y, GA_z, GJ, EI_y, EI_z]`` [N, N, N, N m^2, N m^2, N m^2].
        mass_per_length: [kg/m].
        rotary_inertia: (3,) mass moments of inertia per length about section x, y, z [kg m].
        stress_kind: ``KIND_CIRCULAR``, ``KIND_RECTANGULAR`` or ``KIND_GENERAL``.
        stress_params: (8,) data of :func:`outer_fibre_stresses` (layout per kind there).
        area: [m^2].
    """

    stiffness: np.ndarray
    mass_per_length: float
    rotary_inertia: np.ndarray
    stress_kind: int
    stress_params: np.ndarray
    area: float


def _need(material: Material | None, what: str) -> Material:
    if not isinstance(material, Material):
        raise ModelError(f"{what}: a material (E, G or nu, density) is required, got "
                         f"{material!r}")
    return material


@dataclass(frozen=True)
class SolidCircular:
    """Solid round section of ``diameter`` [m]."""

    diameter: float

    def __post_init__(self) -> None:
        _positive("section.diameter", self.diameter, "m")

    def properties(self, material: Material | None) -> SectionProperties:
        return HollowCircular(self.diameter, 0.0).properties(material)


@dataclass(frozen=True)
class HollowCircular:
    """Tube of ``outer_diameter`` and ``inner_diameter`` [m] (0 <= inner < outer)."""

    outer_diameter: float
    inner_diameter: float

    def __post_init__(self) -> None:
        do = _positive("section.outer_diameter", self.outer_diameter, "m")
        try:
            di = float(self.inner_diameter)
        except (TypeError, ValueError):
            raise ModelError(f"section.inner_diameter: expected a number [m], got "
                             f"{self.inner_diameter!r}") from None
        if not math.isfinite(di) or di < 0.0 or di >= do:
            raise ModelError(f"section.inner_diameter: must be >= 0 and < outer_diameter "
                             f"({do:g} m), got {self.inner_diameter!r}")

    def properties(self, material: Material | None) -> SectionProperties:
        mat = _need(material, "section")
        ro = 0.5 * float(self.outer_diameter)
        ri = 0.5 * float(self.inner_diameter)
        A = math.pi * (ro**2 - ri**2)
        I = math.pi * (ro**4 - ri**4) / 4.0
        Jp = 2.0 * I
        nu = mat.nu
        m2 = (ri / ro) ** 2
        # Cowper (1966), hollow circle; m = 0 gives the solid 6(1+nu)/(7+6nu)
        k = 6 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)
        kappa = 4.0 / 3.0 * (ro**2 + ro * ri + ri**2) / (ro**2 + ri**2)
        rho = mat.density
        return SectionProperties(
            np.array([mat.E * A, k * mat.G * A, k * mat.G * A, mat.G * Jp, mat.E * I, mat.E * I]),
            rho * A, np.array([rho * Jp, rho * I, rho * I]), KIND_CIRCULAR,
            np.array([A, I, Jp, ro, kappa, 0.0, 0.0, 0.0]), A)


def rectangle_torsion(a: float, b: float, terms: int = 4000) -> tuple[float, float, float]:
    """Saint-Venant torsion of an ``a x b`` rectangle (``a >= b``), Timoshenko & Goodier's
    series: ``J = beta a b^3`` and ``tau_max = T / (alpha a b^2)`` at the middle of the long
    sides; also ``k_short``: the shear at the middle of the short sides over ``tau_max``.
    Returns ``(beta, alpha, k_short)``."""
    r = a / b
    n = np.arange(1, 2 * terms, 2, dtype=float)
    x = n * np.pi * r / 2
    sech = 2.0 * np.exp(-x) / (1.0 + np.exp(-2.0 * x))  # 1/cosh without overflow
    beta = (1.0 - 192.0 / (np.pi**5 * r) * np.sum(np.tanh(x) / n**5)) / 3.0
    # Prandtl stress function (Timoshenko & Goodier, sec. 109); with theta' = T / (G J):
    # long side middle  tau = G theta' b (1 - 8/pi^2 sum 1/(n^2 cosh x_n))
    # short side middle tau = G theta' b (8/pi^2) sum (-1)^((n-1)/2) tanh(x_n) / n^2
    s_long = 1.0 - 8.0 / np.pi**2 * np.sum(sech / n**2)
    alpha = beta / s_long
    sgn = np.where(((n - 1) / 2) % 2 == 0, 1.0, -1.0)
    s_short = 8.0 / np.pi**2 * np.sum(sgn * np.tanh(x) / n**2)
    return float(beta), float(alpha), float(s_short / s_long)


@dataclass(frozen=True)
class Rectangular:
    """Solid rectangle ``width_y`` (along section y) x ``height_z`` (along z) [m]."""

    width_y: float
    height_z: float

    def __post_init__(self) -> None:
        _positive("section.width_y", self.width_y, "m")
        _positive("section.height_z", self.height_z, "m")

    def properties(self, material: Material | None) -> SectionProperties:
        mat = _need(material, "section")
        b = float(self.width_y)
        h = float(self.height_z)
        A = b * h
        Iy = b * h**3 / 12.0
        Iz = h * b**3 / 12.0
        long, short = max(b, h), min(b, h)
        beta, alpha, k_short = rectangle_torsion(long, short)
        J = beta * long * short**3
        Wt = alpha * long * short**2
        nu = mat.nu
        k = 10 * (1 + nu) / (12 + 11 * nu)
        rho = mat.density
        return SectionProperties(
            np.array([mat.E * A, k * mat.G * A, k * mat.G * A, mat.G * J, mat.E * Iy,
                      mat.E * Iz]),
            rho * A, np.array([rho * (Iy + Iz), rho * Iy, rho * Iz]), KIND_RECTANGULAR,
            np.array([A, Iy, Iz, b, h, Wt, k_short, 1.0 if b >= h else 0.0]), A)


@dataclass(frozen=True)
class HollowRectangular:
    """Box (hollow rectangle) ``width_y`` (along section y) x ``height_z`` (along z) [m],
    outer dimensions, uniform wall ``thickness`` [m] (``2 thickness < min(width, height)``).

    Area and second moments are exact for the sharp-cornered box; the torsion constant is
    Bredt's thin-walled value ``J = 4 A_m^2 t / p_m`` on the wall's mid-line (``A_m =
    (b - t)(h - t)`` the enclosed area, ``p_m = 2 (b + h - 2 t)`` its perimeter); the shear
    coefficients are Cowper's (1966) for the thin-walled box, for shear along z
    ``k = 10 (1 + nu)(1 + 3 m)^2 / (12 + 72 m + 150 m^2 + 90 m^3 + nu (11 + 66 m + 135 m^2
    + 90 m^3) + 10 n^2 ((3 + nu) m + 3 m^2))`` with ``m = n = b / h`` (``b <-> h`` for y).
    """

    width_y: float
    height_z: float
    thickness: float

    def __post_init__(self) -> None:
        b = _positive("section.width_y", self.width_y, "m")
        h = _positive("section.height_z", self.height_z, "m")
        t = _positive("section.thickness", self.thickness, "m")
        if not 2.0 * t < min(b, h):
            raise ModelError(f"section.thickness: must be < half the smaller outer dimension "
                             f"({0.5 * min(b, h):g} m), got {self.thickness!r}")

    def properties(self, material: Material | None) -> SectionProperties:
        mat = _need(material, "section")
        b = float(self.width_y)
        h = float(self.height_z)
        t = float(self.thickness)
        bi, hi = b - 2.0 * t, h - 2.0 * t
        A = b * h - bi * hi
        Iy = (b * h**3 - bi * hi**3) / 12.0
        Iz = (h * b**3 - hi * bi**3) / 12.0
        Am = (b - t) * (h - t)
        J = 4.0 * Am**2 * t / (2.0 * (b + h - 2.0 * t))
        nu = mat.nu

        def cowper(m: float) -> float:  # thin-walled box, equal walls: m = n
            return (10 * (1 + nu) * (1 + 3 * m) ** 2
                    / (12 + 72 * m + 150 * m**2 + 90 * m**3
                       + nu * (11 + 66 * m + 135 * m**2 + 90 * m**3)
                       + 10 * m**2 * ((3 + nu) * m + 3 * m**2)))

        ky = cowper(h / b)  # shear along y: the walls along y (width b) are the webs
        kz = cowper(b / h)  # shear along z: the walls along z (height h) are the webs
        rho = mat.density
        return SectionProperties(
            np.array([mat.E * A, ky * mat.G * A, kz * mat.G * A, mat.G * J, mat.E * Iy,
                      mat.E * Iz]),
            rho * A, np.array([rho * (Iy + Iz), rho * Iy, rho * Iz]), KIND_BOX,
            np.array([A, Iy, Iz, b, h, t, Am, 0.0]), A)


@dataclass(frozen=True)
class GeneralSection:
    """A section given by its stiffnesses [N, N m^2] and mass per length [kg/m].

    ``rotary_inertia`` (3,) [kg m] per length about x, y, z; default estimated as
    ``m EI/EA`` (``rho I = rho A I/A``). Outer-fibre stresses need ``E`` [Pa] (to recover
    ``A = EA/E``, ``I = EI/E``), the fibre distances ``y_max, z_max`` [m] and the torsion
    modulus ``torsion_modulus`` W_t [m^3] (``tau = T / W_t``); without them they are NaN.
    The von Mises value is then the bound ``sqrt(sigma_max^2 + 3 tau_max^2)`` and
    transverse shear is ignored.
    """

    EA: float
    GAy: float
    GAz: float
    GJ: float
    EIy: float
    EIz: float
    mass_per_length: float
    rotary_inertia: tuple[float, float, float] | None = None
    E: float | None = None
    y_max: float | None = None
    z_max: float | None = None
    torsion_modulus: float | None = None
    _unit: dict = field(default_factory=lambda: {"EA": "N", "GAy": "N", "GAz": "N",
                                                 "GJ": "N m^2", "EIy": "N m^2",
                                                 "EIz": "N m^2", "mass_per_length": "kg/m"},
                        repr=False, compare=False)

    def __post_init__(self) -> None:
        for f, u in self._unit.items():
            _positive(f"section.{f}", getattr(self, f), u)
        for f, u in (("E", "Pa"), ("y_max", "m"), ("z_max", "m"), ("torsion_modulus", "m^3")):
            if getattr(self, f) is not None:
                _positive(f"section.{f}", getattr(self, f), u)
        if self.rotary_inertia is not None:
            r = np.asarray(self.rotary_inertia, dtype=float)
            if r.shape != (3,) or not np.all(np.isfinite(r)) or np.any(r <= 0):
                raise ModelError("section.rotary_inertia: expected 3 numbers > 0 [kg m], got "
                                 f"{self.rotary_inertia!r}")

    def properties(self, material: Material | None = None) -> SectionProperties:
        m = float(self.mass_per_length)
        if self.rotary_inertia is None:
            ry = m * self.EIy / self.EA
            rz = m * self.EIz / self.EA
            rot = np.array([ry + rz, ry, rz])
        else:
            rot = np.asarray(self.rotary_inertia, dtype=float)
        nan = float("nan")
        p = np.full(8, nan)
        if self.E is not None:
            p[0] = self.EA / self.E
            p[1] = self.EIy / self.E
            p[2] = self.EIz / self.E
        p[3] = nan if self.y_max is None else self.y_max
        p[4] = nan if self.z_max is None else self.z_max
        p[5] = nan if self.torsion_modulus is None else self.torsion_modulus
        return SectionProperties(
            np.array([self.EA, self.GAy, self.GAz, self.GJ, self.EIy, self.EIz], float), m,
            rot, KIND_GENERAL, p, nan if self.E is None else self.EA / self.E)


@njit(cache=True, inline="always")
def _vm(s, t):
    return np.sqrt(s * s + 3.0 * t * t)


@njit(cache=True)
def outer_fibre_stresses(kind, p, N, Vy, Vz, T, My, Mz):
    """Largest normal stress ``|sigma_x|``, shear stress ``|tau|`` and von Mises stress
    ``sqrt(sigma^2 + 3 tau^2)`` [Pa] on the outer fibre of a section under the section
    forces ``N, V_y, V_z`` [N] and moments ``T, M_y, M_z`` [N m].

    ``p`` (8,) per kind:

    * circular ``[A, I, J_p, r_o, kappa, -, -, -]``: the normal stress exactly
      (``|N|/A + |M| r_o / I``), shear and von Mises on 32 points of the outer circle; shear
      along the circle ``T r_o / J_p + kappa (V . t) / A`` (``kappa``: Jourawski's factor
      at the neutral axis, 4/3 solid, 2 thin tube; ``t`` the circle's tangent);
    * rectangular ``[A, I_y, I_z, b, h, W_t, k_short, b >= h]``: the 4 corners (no shear
      there) and the 4 mid-edges (torsion ``T / W_t`` on the long sides, ``k_short`` times
      it on the short ones, plus ``1.5 V / A`` of the shear force along that edge, whose
      neutral axis ends there);
    * box ``[A, I_y, I_z, b, h, t, A_m, -]`` (thin-walled shear flows): the 4 mid-edges
      as the rectangle, with Bredt's torsional shear ``T / (2 A_m t)`` on every wall and the
      transverse shear at the neutral axis ``V Q / (2 t I)`` (``Q`` the first moment of
      half the section); the 4 corners with the normal stress and the bound
      ``|T| / (2 A_m t) + (|V_y| / I_z + |V_z| / I_y) A_m / 4`` of the shear there (the
      transverse shear flow at a corner of the thin box is ``V A_m / (4 I)``);
    * general ``[A, I_y, I_z, y_max, z_max, W_t, -, -]``: the bound
      ``|N|/A + |M_y| z_max / I_y + |M_z| y_max / I_z`` and ``|T| / W_t`` (NaN if missing).
    """
    smax = 0.0
    tmax = 0.0
    vm = 0.0
    if kind == KIND_CIRCULAR:
        A, I, Jp, r, kap = p[0], p[1], p[2], p[3], p[4]
        tt = T * r / Jp
        for k in range(_NPTS):
            c = _COS[k]
            s = _SIN[k]
            sig = N / A + (My * r * s - Mz * r * c) / I
            tau = tt + kap * (-Vy * s + Vz * c) / A
            tmax = max(tmax, abs(tau))
            vm = max(vm, _vm(sig, tau))
        # the normal stress is largest where the bending moment vector's normal points:
        # exact, not sampled
        smax = abs(N) / A + np.sqrt(My * My + Mz * Mz) * r / I
        vm = max(vm, smax)
    elif kind == KIND_RECTANGULAR:
        A, Iy, Iz, b, h, Wt, ks, b_long = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
        tl = T / Wt
        ty = tl if b_long > 0.5 else ks * tl  # on the edges z = +-h/2 (length b)
        tz = ks * tl if b_long > 0.5 else tl  # on the edges y = +-b/2 (length h)
        for sy in (-1.0, 1.0):
            for sz in (-1.0, 1.0):
                sig = N / A + My * sz * 0.5 * h / Iy - Mz * sy * 0.5 * b / Iz
                smax = max(smax, abs(sig))
                vm = max(vm, abs(sig))
        for sgn in (-1.0, 1.0):
            # mid of the edge z = sgn h/2: shear along y (torsion circulates: sign -sgn)
            sig = N / A + My * sgn * 0.5 * h / Iy
            tau = -sgn * ty + 1.5 * Vy / A
            smax = max(smax, abs(sig))
            tmax = max(tmax, abs(tau))
            vm = max(vm, _vm(sig, tau))
            # mid of the edge y = sgn b/2: shear along z (torsion sign +sgn)
            sig = N / A - Mz * sgn * 0.5 * b / Iz
            tau = sgn * tz + 1.5 * Vz / A
            smax = max(smax, abs(sig))
            tmax = max(tmax, abs(tau))
            vm = max(vm, _vm(sig, tau))
    elif kind == KIND_BOX:
        A, Iy, Iz, b, h, t, Am = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
        tl = T / (2.0 * Am * t)  # Bredt: the same shear on every wall
        fy = (h * b * b - (h - 2 * t) * (b - 2 * t) ** 2) / (16.0 * t * Iz)  # Q_z / (2 t I_z)
        fz = (b * h * h - (b - 2 * t) * (h - 2 * t) ** 2) / (16.0 * t * Iy)  # Q_y / (2 t I_y)
        tc = abs(tl) + 0.25 * Am * (abs(Vy) / Iz + abs(Vz) / Iy)
        for sy in (-1.0, 1.0):
            for sz in (-1.0, 1.0):
                sig = N / A + My * sz * 0.5 * h / Iy - Mz * sy * 0.5 * b / Iz
                smax = max(smax, abs(sig))
                vm = max(vm, _vm(sig, tc))
        tmax = tc
        for sgn in (-1.0, 1.0):
            sig = N / A + My * sgn * 0.5 * h / Iy
            tau = -sgn * tl + fy * Vy
            smax = max(smax, abs(sig))
            tmax = max(tmax, abs(tau))
            vm = max(vm, _vm(sig, tau))
            sig = N / A - Mz * sgn * 0.5 * b / Iz
            tau = sgn * tl + fz * Vz
            smax = max(smax, abs(sig))
            tmax = max(tmax, abs(tau))
            vm = max(vm, _vm(sig, tau))
    else:
        smax = abs(N) / p[0] + abs(My) * p[4] / p[1] + abs(Mz) * p[3] / p[2]
        tmax = abs(T) / p[5]
        vm = _vm(smax, tmax)
    return smax, tmax, vm


@njit(cache=True)
def _stress_rows(kind, p, F, out):
    for k in range(F.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = outer_fibre_stresses(
            kind, p, F[k, 0], F[k, 1], F[k, 2], F[k, 3], F[k, 4], F[k, 5])


def section_stresses(kind: np.ndarray, params: np.ndarray, ei: int,
                     forces: np.ndarray) -> np.ndarray:
    """Outer-fibre stresses (nt, 3) [Pa] (``|sigma_x|``, ``|tau|``, von Mises: see
    :func:`outer_fibre_stresses`) of element ``ei`` of a beam group whose sections are
    ``kind`` (nel,) and ``params`` (nel, 8), from its section forces ``forces`` (nt, 6)
    ``N, V_y, V_z`` [N], ``T, M_y, M_z`` [N m]: the beam family's derived outputs."""
    F = np.ascontiguousarray(forces, dtype=float)
    out = np.empty((F.shape[0], 3))
    _stress_rows(int(kind[ei]), np.ascontiguousarray(params[ei]), F, out)
    return out
