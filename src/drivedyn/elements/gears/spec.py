"""The gear pair's parameter record (the spec the user writes) and its checks."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from drivedyn.elements.framework.checks import check_param, check_param_optional, unit_of
from drivedyn.elements.framework.registry import TwoMarkerSpec
from drivedyn.elements.gears.geometry import undercut_limits
from drivedyn.errors import ModelError

KINDS = ("parallel", "bevel", "crossed")


@dataclass(frozen=True)
class GearPair(TwoMarkerSpec):
    """A gear mesh between wheel A (``marker_a``) and wheel B (``marker_b``).

    Each marker sits at its wheel's centre with its z axis along the wheel axis: for spur,
    helical and internal pairs (``kind="parallel"``) at the centre of the wheel in the
    mid-face plane; for bevel pairs at the centre of the mean pitch circle; for crossed-axis
    helical and worm pairs at the point of the wheel axis on the common perpendicular of the
    axes. The markers may sit on rigid bodies, nodes or the ground (one of the two wheels).
    The initial configuration must be assembled: the centre distance (or cone distances,
    shaft angle) must match the gear data within ``tolerance``, otherwise :class:`ModelError`.

    Attributes:
        name: unique element name.
        marker_a, marker_b: wheel markers (z axis = wheel axis).
        teeth_a, teeth_b: tooth numbers (> 0; a worm's number of starts for wheel A).
        module: normal module m_n [m] (bevel: at the mean cone distance).
        face_width: b [m] (used by the ISO 6336 stiffness).
        pressure_angle: normal pressure angle alpha_n [rad] (0 < alpha_n < 45 deg).
        helix_angle: helix angle beta of wheel A [rad] at the reference (pitch) cylinder,
            positive for a right hand (bevel: mean spiral angle; worm: 90 deg - lead angle).
        helix_angle_b: helix angle of wheel B [rad]; required for ``"crossed"``; for the other
            kinds it is checked (external and bevel pairs: ``-helix_angle``, internal pairs:
            ``helix_angle``) when given.
        kind: ``"parallel"`` (spur, helical, internal), ``"bevel"`` (intersecting axes,
            conical pitch surfaces) or ``"crossed"`` (skew axes: crossed helical, worm).
        internal: ``None`` (external pair), ``"a"`` or ``"b"``: which wheel is the ring
            (internal gear); parallel pairs only.
        cone_angle_a, cone_angle_b: pitch cone angles [rad] (bevel; 0 < gamma <= 90 deg, the
            shaft angle is their sum).
        profile_shift_a, profile_shift_b: profile shift coefficients x (ISO 21771 signs).
        addendum: addendum of the basic rack over the module, h_aP / m_n.
        dedendum: dedendum of the basic rack over the module, h_fP / m_n (ISO C_B factor).
        stiffness: mean mesh stiffness k_m [N/m] along the tooth normal; None = ISO 6336-1
            method B from the geometry (parallel and bevel pairs).
        stiffness_variation: vary k_m over the mesh cycle with the number of tooth pairs in
            contact (from the transverse contact ratio); the mean stays ``stiffness``.
        contact_ratio: transverse contact ratio eps_alpha; None = from the geometry.
        variation_smoothing: width of the smoothed stiffness steps, fraction of a mesh cycle.
        mesh_phase: mesh-cycle phase at t = 0, fraction of a cycle (0: a double-contact
            zone starts).
        damping: mesh damping c_m [N s/m] along the tooth normal.
        damping_ratio: zeta; c_m = 2 zeta sqrt(k_m m_e) with the equivalent mass of the
            wheels' rotary inertias about their axes (exclusive with ``damping``).
        backlash: hoop backlash b [m] measured along the line of action in the transverse
            plane of wheel A (base tangent): with B held, A turns freely by b / r_bA.
        initial_gap: gap on the drive flank at t = 0 [m], same measure, 0 <= gap <= backlash.
        transmission_error: amplitude X [m] of the loaded transmission error
            X (1 - cos(z_A psi_A)) along the tooth normal (psi_A: rotation of A in the mesh).
        flank_onset: approach d [m] over which a flank's stiffness rises from 0 to k_m (a C1
            onset, force k u^2/(2d), then k (u - d/2)); 0: the sharp law k u. A numerical
            regularisation for flanks that close and open at zero torque (set it far below
            the loaded deflection, e.g. 20 nm).
        friction: tooth friction coefficient mu (0: none).
        friction_velocity: regularisation speed eps_v [m/s] of the friction law.
        youngs_modulus: equivalent Young's modulus 2 E1 E2 / (E1 + E2) [Pa] for ISO 6336.
        rim_factor: ISO 6336 gear blank factor C_R (1: solid disc).
        max_misalignment: largest initial angle between the axes of a parallel pair [rad].
        tolerance: relative tolerance of the assembly checks (centre and cone distances);
            angles are checked to the same value in rad.
    """

    teeth_a: int
    teeth_b: int
    module: float
    face_width: float
    pressure_angle: float = float(np.radians(20.0))
    helix_angle: float = 0.0
    helix_angle_b: float | None = None
    kind: str = "parallel"
    internal: str | None = None
    cone_angle_a: float | None = None
    cone_angle_b: float | None = None
    profile_shift_a: float = 0.0
    profile_shift_b: float = 0.0
    addendum: float = 1.0
    dedendum: float = 1.25
    stiffness: float | None = None
    stiffness_variation: bool = False
    contact_ratio: float | None = None
    variation_smoothing: float = 0.05
    mesh_phase: float = 0.0
    damping: float | None = None
    damping_ratio: float | None = None
    backlash: float = 0.0
    initial_gap: float = 0.0
    transmission_error: float = 0.0
    flank_onset: float = 0.0
    friction: float = 0.0
    friction_velocity: float = 1e-3
    youngs_modulus: float = 206e9
    rim_factor: float = 1.0
    max_misalignment: float = float(np.radians(1.0))
    tolerance: float = 1e-3
    family: ClassVar[str] = "gear_pair"
    units: ClassVar[dict[str, str]] = {
        "module": "m", "face_width": "m", "pressure_angle": "rad", "helix_angle": "rad",
        "helix_angle_b": "rad", "cone_angle_a": "rad", "cone_angle_b": "rad",
        "stiffness": "N/m", "damping": "N s/m", "backlash": "m", "initial_gap": "m",
        "transmission_error": "m", "flank_onset": "m", "friction_velocity": "m/s",
        "youngs_modulus": "Pa", "max_misalignment": "rad",
        # dimensionless: shift coefficients and rack proportions (over the module), ratios,
        # fractions of a mesh cycle, the friction coefficient, the relative tolerance
        "profile_shift_a": "1", "profile_shift_b": "1", "addendum": "1", "dedendum": "1",
        "contact_ratio": "1", "variation_smoothing": "1", "mesh_phase": "1",
        "damping_ratio": "1", "friction": "1", "rim_factor": "1", "tolerance": "1",
    }

    def visuals(self) -> tuple:
        """The two wheels as toothed wheels on their markers: pitch radius z m_n / (2 cos
        beta) (bevel: z m_n / 2 at the mean cone, with its cone angle), the tooth count, face
        width and helix of each (the profile shift is not drawn), and for parallel axes the
        mesh force at the pitch point."""
        from drivedyn.elements.framework.visuals import gear, point_force

        beta_a = float(self.helix_angle)
        if self.helix_angle_b is not None:
            beta_b = float(self.helix_angle_b)
        else:  # an external pair has opposite hands, an internal pair the same hand
            beta_b = beta_a if self.internal else -beta_a
        out = []
        for marker, z, beta, cone, internal in (
                (self.marker_a, self.teeth_a, beta_a, self.cone_angle_a, self.internal == "a"),
                (self.marker_b, self.teeth_b, beta_b, self.cone_angle_b, self.internal == "b")):
            bevel = self.kind == "bevel"
            r = 0.5 * z * self.module / (1.0 if bevel else np.cos(beta))
            out.append(gear(marker, int(z), r, self.face_width, self.module,
                            helix_angle=0.0 if bevel else beta, internal=internal,
                            cone_angle=float(cone or 0.0) if bevel else 0.0, label=self.name))
        if self.kind == "parallel":
            # the mesh force on wheel B at the pitch point: from A's centre towards B's at
            # A's pitch radius (away from B's when A is a pinion inside ring B)
            r_a = out[0].values["pitch_radius"]
            out.append(point_force(self.marker_a, self.marker_b, f"{self.name}.force",
                                   -r_a if self.internal == "b" else r_a, label=self.name))
        return tuple(out)

    def _fail(self, label: str, msg: str, value) -> None:
        raise ModelError(f"GearPair {self.name!r}.{label}: {msg}, got {value!r}")

    def validate(self) -> None:
        for label in ("teeth_a", "teeth_b"):
            val = getattr(self, label)
            if isinstance(val, bool) or int(val) != val or val <= 0:
                self._fail(label, "must be a positive whole number of teeth", val)
        for label in ("module", "face_width", "friction_velocity", "youngs_modulus",
                      "rim_factor", "tolerance", "addendum", "dedendum"):
            check_param(self, label, 0.0, strict=True)
        for label in ("backlash", "initial_gap", "transmission_error", "flank_onset",
                      "friction", "max_misalignment"):
            check_param(self, label, 0.0)
        for label in ("pressure_angle", "helix_angle", "profile_shift_a", "profile_shift_b",
                      "variation_smoothing", "mesh_phase"):
            check_param(self, label)
        for label in ("helix_angle_b", "cone_angle_a", "cone_angle_b"):
            check_param_optional(self, label)
        if not 0.0 < self.pressure_angle < np.radians(45.0):
            self._fail("pressure_angle", "must be in (0, 45 deg) [rad]", self.pressure_angle)
        for label in ("helix_angle", "helix_angle_b"):
            val = getattr(self, label)
            if val is not None and not abs(val) < 0.5 * np.pi:
                self._fail(label, "|beta| must be < 90 deg [rad]", val)
        if self.kind not in KINDS:
            self._fail("kind", f"must be one of {KINDS}", self.kind)
        if self.internal not in (None, "a", "b"):
            self._fail("internal", "must be None, 'a' or 'b' (the ring gear)", self.internal)
        if self.internal is not None:
            if self.kind != "parallel":
                self._fail("internal", "internal gears are supported for parallel axes only",
                           self.internal)
            ring, pinion = ((self.teeth_a, self.teeth_b) if self.internal == "a"
                            else (self.teeth_b, self.teeth_a))
            if ring <= pinion:
                self._fail(f"teeth_{self.internal}", "the ring gear needs more teeth than the "
                           f"pinion ({pinion})", ring)
        if self.initial_gap > self.backlash:
            self._fail("initial_gap", f"must not exceed the backlash {self.backlash!r} "
                       f"{unit_of(self, 'backlash')}", self.initial_gap)
        check_param_optional(self, "stiffness", 0.0, strict=True)
        if self.damping is not None and self.damping_ratio is not None:
            self._fail("damping_ratio", "give either damping or damping_ratio",
                       self.damping_ratio)
        check_param_optional(self, "damping", 0.0)
        check_param_optional(self, "damping_ratio", 0.0)
        check_param_optional(self, "contact_ratio", 1.0)
        if not 0.0 < self.variation_smoothing <= 0.5:
            self._fail("variation_smoothing", "must be in (0, 0.5] (fraction of a mesh cycle)",
                       self.variation_smoothing)
        if self.kind == "bevel":
            for label in ("cone_angle_a", "cone_angle_b"):
                val = getattr(self, label)
                if val is None or not (0.0 < val <= 0.5 * np.pi + 1e-12):
                    self._fail(label, "bevel pairs need a pitch cone angle in (0, 90 deg] "
                               "[rad]", val)
        if self.kind == "crossed":
            if self.helix_angle_b is None:
                self._fail("helix_angle_b", "crossed-axis pairs need the helix angle of "
                           "wheel B", None)
            if self.stiffness is None:
                self._fail("stiffness", "crossed-axis (and worm) pairs need an explicit mesh "
                           "stiffness (ISO 6336 does not cover them)", None)
        self._check_undercut()

    def _check_undercut(self) -> None:
        """Refuse wheels that undercut beyond the practical limit (DIN 3960: slight undercut
        accepted, limit number of teeth 5/6 of the theoretical one): an undercut flank has
        no involute near the root, so the element's involute contact would be fiction. The
        ring of an internal pair and crossed-axis wheels are not checked."""
        if self.kind == "crossed":
            return
        for w, beta in (("a", self.helix_angle),
                        ("b", self.helix_angle if self.helix_angle_b is None
                         else self.helix_angle_b)):
            if self.internal == w:
                continue
            z = float(getattr(self, f"teeth_{w}"))
            cone = getattr(self, f"cone_angle_{w}")
            if self.kind == "bevel" and cone is not None and cone < 0.5 * np.pi - 1e-9:
                z = z / np.cos(cone)  # Tredgold's virtual spur gear
            elif self.kind == "bevel":
                continue  # a crown wheel (90 deg cone) has no undercut
            x = getattr(self, f"profile_shift_{w}")
            z_g, x_th, x_pr = undercut_limits(z, self.pressure_angle, beta, self.addendum)
            if x < x_pr - 1e-12:
                self._fail(f"teeth_{w}", f"the wheel undercuts: {z:g} teeth at "
                           f"{np.degrees(self.pressure_angle):g} deg pressure angle and "
                           f"{np.degrees(abs(beta)):g} deg helix need a profile shift "
                           f"profile_shift_{w} >= {x_pr:.3f} (no undercut at all from "
                           f"{x_th:.3f}; at zero shift from {5 * z_g / 6:.1f} teeth; "
                           f"profile_shift_{w} is {x:g})", getattr(self, f"teeth_{w}"))
