"""Tyres: Pacejka's Magic Formula from property files, and the simple B, C, D, E sets.

Example::

    from drivedyn.tyres import read_tir, shipped
    tyre = read_tir(shipped("pac2002_235_60R16"))
    fx, fy, mz = tyre.forces(fz=4000.0, kappa=0.05, alpha=0.02)

Signs and axes are those of the file (TYDEX/ISO-W, :mod:`drivedyn.tyres.magic_formula`). The
tyre *element* that puts a tyre on a wheel body (vertical load from the tyre's deflection,
slips from the wheel's motion, first-order relaxation) is
:class:`drivedyn.elements.tyre.TyreContact`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drivedyn.errors import ModelError
from drivedyn.tyres.magic_formula import INDEX, KIND_SIMPLE, NOUT, OUT_NAMES, evaluate, pack
from drivedyn.tyres.magic_formula import effective_radius as _effective_radius
from drivedyn.tyres.tir import VERSIONS, coefficients, file_side, parse_tir

__all__ = ["SURFACES", "Tyre", "read_tir", "resolve_tyre", "shipped", "shipped_files",
           "side_asymmetry", "simple_tyre"]

DATA = Path(__file__).parent / "data"

#: B, C, D, E of the simple formula by surface (physics.md 5; D is the friction coefficient)
SURFACES: dict[str, tuple[float, float, float, float]] = {
    "dry": (10.0, 1.9, 1.0, 0.97),
    "wet": (12.0, 2.3, 0.82, 1.0),
    "snow": (5.0, 2.0, 0.3, 1.0),
    "ice": (4.0, 2.0, 0.1, 1.0),
}


@dataclass(frozen=True, eq=False)  # compared and hashed by identity (it holds an array)
class Tyre:
    """A tyre: its coefficient array and where it came from.

    Attributes:
        name: file stem or ``"simple-dry"``...
        params: (NPAR,) coefficients (:data:`drivedyn.tyres.magic_formula.KEYS` order).
        version: ``"5.2"``, ``"6.1"``, ``"6.2"`` or ``"simple"``.
        source: file path or description.
    """

    name: str
    params: np.ndarray
    version: str
    source: str

    def value(self, key: str) -> float:
        """One coefficient (``"FNOMIN"``, ``"PCX1"``...)."""
        return float(self.params[INDEX[key]])

    @property
    def unloaded_radius(self) -> float:
        """R0 [m]."""
        return self.value("UNLOADED_RADIUS")

    @property
    def nominal_load(self) -> float:
        """FNOMIN [N]."""
        return self.value("FNOMIN")

    @property
    def vertical_stiffness(self) -> float:
        """Cz [N/m]."""
        return self.value("VERTICAL_STIFFNESS")

    @property
    def vertical_damping(self) -> float:
        """Kz [N s/m]."""
        return self.value("VERTICAL_DAMPING")

    def evaluate(self, fz, kappa, alpha=0.0, gamma=0.0, vx=None, pressure=None,
                 mu=1.0) -> dict[str, np.ndarray]:
        """Every output of the formula (``fx fy mz my kxk kya sigma_kappa sigma_alpha mu_x
        mu_y``, see :func:`~drivedyn.tyres.magic_formula.evaluate`) for inputs that
        broadcast together: ``fz`` [N], ``kappa`` [-], ``alpha``, ``gamma`` [rad], ``vx``
        [m/s] (default the file's LONGVL), ``pressure`` [Pa] (default INFLPRES), ``mu`` road
        friction factor on LMUX/LMUY."""
        vx = self.value("LONGVL") if vx is None else vx
        p = 0.0 if pressure is None else pressure
        b = np.broadcast_arrays(*(np.asarray(a, dtype=float)
                                  for a in (fz, kappa, alpha, gamma, vx, p, mu)))
        out = np.zeros((*b[0].shape, NOUT))
        buf = np.zeros(NOUT)
        for idx in np.ndindex(b[0].shape):
            evaluate(self.params, *(float(a[idx]) for a in b), 1.0, buf)
            out[idx] = buf
        return {n: out[..., i] for i, n in enumerate(OUT_NAMES)}

    def forces(self, fz, kappa, alpha=0.0, gamma=0.0, vx=None, pressure=None, mu=1.0
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Steady-state (Fx [N], Fy [N], Mz [N m]) in the file's TYDEX/ISO-W axes."""
        r = self.evaluate(fz, kappa, alpha, gamma, vx, pressure, mu)
        return r["fx"], r["fy"], r["mz"]

    def relaxation_lengths(self, fz, gamma=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(sigma_kappa, sigma_alpha) [m] at load ``fz`` [N]."""
        r = self.evaluate(fz, 0.0, 0.0, gamma)
        return r["sigma_kappa"], r["sigma_alpha"]

    def effective_radius(self, rho: float) -> float:
        """Effective rolling radius [m] at radial deflection ``rho`` [m]."""
        return float(_effective_radius(self.params, float(rho)))

    def scaled(self, **factors: float) -> Tyre:
        """A copy with scaling factors multiplied (``tyre.scaled(LMUX=0.5)``)."""
        P = self.params.copy()
        for k, f in factors.items():
            if k not in INDEX or not k.startswith("L"):
                raise ModelError(f"tyre {self.name}: {k!r} is not a scaling factor")
            P[INDEX[k]] *= f
        return Tyre(self.name, P, self.version, self.source)


def read_tir(path: str | Path, side: str | None = None, measured: str | None = None) -> Tyre:
    """Read a Magic Formula 5.2 / 6.1 / 6.2 property file; :class:`ModelError` naming the
    section and key for a malformed or incomplete file.

    ``side`` (``"left"`` or ``"right"``): the side of the vehicle the tyre is mounted on. A
    file measured on the other side (``[MODEL] TYRESIDE``) is mirrored
    (:mod:`drivedyn.tyres.magic_formula`, "Sides"); a ``SYMMETRIC`` file, or one without
    ``TYRESIDE``, is used as it is on both sides. None: as the file gives it.
    ``measured`` (``"left"``, ``"right"``, ``"symmetric"``): the side a file without
    ``TYRESIDE`` was measured on (one that has it must agree)."""
    if side is not None and side not in ("left", "right"):
        raise ModelError(f"tyre file {path}: side: expected 'left' or 'right', got {side!r}")
    if measured is not None and measured not in ("left", "right", "symmetric"):
        raise ModelError(f"tyre file {path}: measured: expected 'left', 'right' or "
                         f"'symmetric', got {measured!r}")
    tf = parse_tir(path)
    P, fittyp = coefficients(tf)
    name = Path(path).stem
    given = file_side(tf)
    if measured is not None and given is not None and given != measured:
        raise ModelError(f"tyre file {path}: measured on the {measured} contradicts its "
                         f"[MODEL] TYRESIDE = {given.upper()!r}")
    measured = given or measured
    if side is not None and measured in ("left", "right") and measured != side:
        P = P.copy()
        P[INDEX["MIRROR"]] = 1.0
        name += f" (mirrored to the {side})"
    return Tyre(name, P, VERSIONS[fittyp], str(path))


#: slip angles [rad] and camber angles [rad] at which :func:`side_asymmetry` compares a
#: tyre with its mirror image (at its nominal load)
ASYMMETRY_ALPHA = tuple(np.linspace(-0.15, 0.15, 7))
ASYMMETRY_GAMMA = (-0.05, 0.0, 0.05)


def side_asymmetry(tyre: Tyre) -> float:
    """How much the tyre differs from its mirror image (the same tyre on the other side of
    the vehicle): the largest change of the lateral force and of the aligning moment when
    mirrored, each relative to its own largest magnitude, over slip angles
    :data:`ASYMMETRY_ALPHA` and cambers :data:`ASYMMETRY_GAMMA` at the nominal load and no
    longitudinal slip. 0 for a symmetric tyre (no ply-steer, conicity or one-sided shape
    factor); a simple formula tyre is symmetric."""
    if tyre.version == "simple":
        return 0.0
    mirror = tyre.params.copy()
    mirror[INDEX["MIRROR"]] = 1.0 - mirror[INDEX["MIRROR"]]
    other = Tyre(tyre.name, mirror, tyre.version, tyre.source)
    a, g = np.meshgrid(ASYMMETRY_ALPHA, ASYMMETRY_GAMMA)
    fz = tyre.nominal_load
    r0, r1 = tyre.evaluate(fz, 0.0, a, g), other.evaluate(fz, 0.0, a, g)
    out = 0.0
    for key in ("fy", "mz"):
        scale = float(np.abs(r0[key]).max())
        if scale > 0.0:
            out = max(out, float(np.abs(r0[key] - r1[key]).max()) / scale)
    return out


def simple_tyre(surface: str = "dry", unloaded_radius: float = 0.3,
                vertical_stiffness: float = 2.0e5, vertical_damping: float = 500.0,
                relaxation_length: float = 0.3, rolling_resistance: float = 0.01,
                nominal_load: float = 4000.0, B: float | None = None, C: float | None = None,
                D: float | None = None, E: float | None = None) -> Tyre:
    """The simple formula with the B, C, D, E set of ``surface`` (dry, wet, snow, ice), any of
    which ``B, C, D, E`` override. Radius [m], stiffness [N/m], damping [N s/m], relaxation
    length [m] (both directions), rolling-resistance coefficient [-], nominal load [N]."""
    if surface not in SURFACES:
        raise ModelError(f"simple tyre: surface: expected one of {', '.join(SURFACES)}, got "
                         f"{surface!r}")
    b, c, d, e = SURFACES[surface]
    b, c, d, e = (b if B is None else B, c if C is None else C, d if D is None else D,
                  e if E is None else E)
    for label, v in (("B", b), ("C", c), ("D", d), ("unloaded_radius", unloaded_radius),
                     ("vertical_stiffness", vertical_stiffness),
                     ("relaxation_length", relaxation_length),
                     ("nominal_load", nominal_load)):
        if not np.isfinite(v) or v <= 0.0:
            raise ModelError(f"simple tyre: {label}: must be > 0, got {v!r}")
    if not e <= 1.0:
        raise ModelError(f"simple tyre: E: must be <= 1, got {e!r}")
    P = pack({"KIND": KIND_SIMPLE, "SIMPLE_B": b, "SIMPLE_C": c, "SIMPLE_D": d, "SIMPLE_E": e,
              "SIMPLE_SIGMA": relaxation_length, "SIMPLE_RR": rolling_resistance,
              "UNLOADED_RADIUS": unloaded_radius, "VERTICAL_STIFFNESS": vertical_stiffness,
              "VERTICAL_DAMPING": vertical_damping, "FNOMIN": nominal_load})
    return Tyre(f"simple-{surface}", P, "simple", f"simple B, C, D, E set '{surface}'")


def shipped_files() -> list[str]:
    """Names of the property files shipped with drivedyn."""
    return sorted(p.stem for p in DATA.glob("*.tir"))


def shipped(name: str) -> Path:
    """Path of a shipped property file by name (without ``.tir``)."""
    p = DATA / f"{name}.tir"
    if not p.exists():
        raise ModelError(f"tyre {name!r}: no such shipped file (shipped: "
                         f"{', '.join(shipped_files())})")
    return p


def resolve_tyre(value: Tyre | str, side: str | None = None) -> Tyre:
    """A :class:`Tyre` as given, or from a string: ``simple-<dry|wet|snow|ice>``, the name of
    a shipped property file, or the path of a ``.tir`` file, read for a wheel on ``side``
    (``"left"``/``"right"``: a file measured on the other side is mirrored, :func:`read_tir`;
    None: as the file gives it). A :class:`Tyre` object is used as it is (read it with
    ``read_tir(path, side=...)``)."""
    if isinstance(value, Tyre):
        return value
    if not isinstance(value, str):
        raise ModelError(f"tyre: expected a Tyre, a shipped tyre name, simple-<surface> or a "
                         f".tir path, got {type(value).__name__}")
    if value.startswith("simple-"):
        return simple_tyre(value.removeprefix("simple-"))
    if value in shipped_files():
        return read_tir(shipped(value), side)
    if not Path(value).exists():
        known = ", ".join(shipped_files())
        raise ModelError(f"tyre: {value!r} is neither a shipped tyre ({known}), "
                         "simple-<dry|wet|snow|ice> nor an existing .tir file")
    return read_tir(value, side)
