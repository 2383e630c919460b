"""The beam element spec and its registry entry (family ``beam``).

A :class:`GeometricallyExactBeam` joins two nodes (plain nodes or rigid bodies' nodes); its
section frame at each end is the node frame times a constant rotation fixed at build time
(see :mod:`~drivedyn.elements.beams.kernel` for the formulation). Chains of elements sharing
nodes make shafts and frames; :func:`drivedyn.model.beams.add_straight_beam` builds them.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Any, ClassVar

import numpy as np

from drivedyn.elements.beams.kernel import WORK_SIZE, beam_kernel
from drivedyn.elements.beams.se3 import log_se3
from drivedyn.elements.beams.section import Material, SectionProperties, section_stresses
from drivedyn.elements.framework.building import make_group, node_dofs, what_of
from drivedyn.elements.framework.checks import check_param
from drivedyn.elements.framework.group import DerivedOutputs, Group
from drivedyn.elements.framework.registry import ElementSpec, Family, register
from drivedyn.errors import ModelError, did_you_mean

#: per-element outputs (aux columns in this order)
OUTPUTS = (
    ("axial_force", "N", "axial force N (tension positive) at the element's Gauss point"),
    ("shear_force_y", "N", "shear force V_y, section frame"),
    ("shear_force_z", "N", "shear force V_z, section frame"),
    ("torque", "N m", "torsional moment T about the beam axis"),
    ("bending_moment_y", "N m", "bending moment M_y about the section y axis"),
    ("bending_moment_z", "N m", "bending moment M_z about the section z axis"),
    ("axial_strain", "1", "axial strain of the centre line"),
    ("shear_strain_y", "1", "shear strain y"),
    ("shear_strain_z", "1", "shear strain z"),
    ("twist", "rad/m", "rate of twist"),
    ("curvature_y", "1/m", "curvature about the section y axis"),
    ("curvature_z", "1/m", "curvature about the section z axis"),
    ("normal_stress", "Pa", "largest |axial + bending normal stress| on the outer fibre"),
    ("shear_stress", "Pa", "largest |torsional + transverse shear stress| on the outer fibre"),
    ("von_mises", "Pa", "largest von Mises stress on the outer fibre"),
    ("elastic_energy", "J", "strain energy of the element"),
)
#: the section forces, and the stresses computed from them when read (not by the kernel)
FORCE_COLUMNS = (0, 1, 2, 3, 4, 5)
STRESS_COLUMNS = (12, 13, 14)


@dataclass(frozen=True)
class GeometricallyExactBeam(ElementSpec):
    """A two-node geometrically exact (SE(3)) beam element.

    Attributes:
        name: unique element name.
        node_a, node_b: the end nodes (names of nodes or rigid bodies).
        section: a section of :mod:`drivedyn.elements.beams.section` (``SolidCircular``,
            ``HollowCircular``, ``Rectangular``, ``GeneralSection``).
        material: :class:`Material` (not needed by a ``GeneralSection``).
        orientation: (3,) global vector fixing the section's y axis (its component normal to
            the beam axis); None picks the global axis most normal to the beam. Ignored
            when ``curved``.
        damping: stiffness-proportional material damping ``beta`` [s]: section forces
            ``K_s (eps + beta epsdot)``.
        curved: if True, the section frames are the initial node frames themselves (x along
            the centre line) and the initial shape is the SE(3) helix between them
            (constant curvature and twist, stress free); if False the element is straight
            between the node origins.
        mass_matrix: translational mass ``"lumped"`` (default: the more accurate with this
            element, see :mod:`~drivedyn.elements.beams.kernel`) or ``"consistent"``.
    """

    family: ClassVar[str] = "beam"
    units: ClassVar[dict[str, str]] = {"damping": "s"}
    name: str
    node_a: str
    node_b: str
    section: Any
    material: Material | None = None
    orientation: Any = None
    damping: float = 0.0
    curved: bool = False
    mass_matrix: str = "lumped"

    def properties(self) -> SectionProperties:
        """Section stiffness, mass and stress data (ModelError naming the element)."""
        try:
            return self.section.properties(self.material)
        except ModelError as exc:
            raise ModelError(f"{what_of(self)}: {exc}") from None
        except AttributeError:
            raise ModelError(f"{what_of(self)}.section: expected a beam section, got "
                             f"{self.section!r}") from None

    def validate(self) -> None:
        what = what_of(self)
        check_param(self, "damping", 0.0)
        if self.node_a == self.node_b:
            raise ModelError(f"{what}: node_a and node_b are the same node {self.node_a!r}")
        self.properties()
        if self.mass_matrix not in ("lumped", "consistent"):
            raise ModelError(f"{what}.mass_matrix: expected 'lumped' or 'consistent', got "
                             f"{self.mass_matrix!r}")
        if self.orientation is not None:
            o = np.asarray(self.orientation, dtype=float)
            if o.shape != (3,) or not np.all(np.isfinite(o)) or np.linalg.norm(o) == 0.0:
                raise ModelError(f"{what}.orientation: expected a non-zero vector of 3 numbers, "
                                 f"got {self.orientation!r}")


def section_frame(axis: np.ndarray, orientation: Any, what: str) -> np.ndarray:
    """Rotation (3, 3) whose x column is ``axis`` (unit) and y column the part of
    ``orientation`` normal to it (default: the global axis most normal to ``axis``)."""
    ex = axis / np.linalg.norm(axis)
    if orientation is None:
        o = np.eye(3)[int(np.argmin(np.abs(ex)))]
    else:
        o = np.asarray(orientation, dtype=float)
    ey = o - (o @ ex) * ex
    n = np.linalg.norm(ey)
    if n < 1e-6 * np.linalg.norm(o):
        raise ModelError(f"{what}.orientation: {list(map(float, o))} is parallel to the beam "
                         "axis; give a vector across it")
    ey /= n
    return np.column_stack([ex, ey, np.cross(ex, ey)])


class BeamFamily(Family):
    """Registry entry of :class:`GeometricallyExactBeam`."""

    name = "beam"
    spec_types = (GeometricallyExactBeam,)

    def build(self, specs, ctx) -> Group:
        nel = len(specs)
        lnodes = np.zeros((nel, 2), np.int64)
        length = np.zeros(nel)
        eps0 = np.zeros((nel, 6))
        Ks = np.zeros((nel, 6))
        CA = np.zeros((nel, 3, 3))
        CB = np.zeros((nel, 3, 3))
        mass = np.zeros(nel)
        cmix = np.zeros(nel)
        Jn = np.zeros((nel, 2, 3, 3))
        skind = np.zeros(nel, np.int64)
        spar = np.zeros((nel, 8))
        beta = np.zeros(nel)
        d0 = np.zeros(6)
        for e, s in enumerate(specs):
            what = what_of(s)
            for k, nm in enumerate((s.node_a, s.node_b)):
                if nm not in ctx.node_index:
                    label = "node_a" if k == 0 else "node_b"
                    raise ModelError(f"{what}.{label}: unknown node {nm!r}"
                                     f"{did_you_mean(nm, ctx.node_index)}")
                lnodes[e, k] = ctx.node_index[nm]
            nA, nB = lnodes[e]
            xA, xB = ctx.x0[nA], ctx.x0[nB]
            RA, RB = ctx.R0[nA], ctx.R0[nB]
            chord = xB - xA
            if s.curved:
                CA[e] = np.eye(3)
                CB[e] = np.eye(3)
                log_se3(xA, RA, xB, RB, d0)
                L = float(np.linalg.norm(d0[:3]))
            else:
                L = float(np.linalg.norm(chord))
            scale = max(1.0, float(np.abs(xA).max()), float(np.abs(xB).max()))
            if not L > 1e-9 * scale:
                raise ModelError(f"{what}: zero-length element (nodes {s.node_a!r} and "
                                 f"{s.node_b!r} are both at {xA.tolist()} m)")
            if s.curved:
                eps0[e] = d0 / L
            else:
                Rs = section_frame(chord, s.orientation, what)
                CA[e] = RA.T @ Rs
                CB[e] = RB.T @ Rs
                eps0[e, 0] = 1.0
            p = s.properties()
            length[e] = L
            Ks[e] = p.stiffness
            mass[e] = p.mass_per_length * L
            cmix[e] = 1.0 if s.mass_matrix == "consistent" else 0.0
            Jsec = np.diag(p.rotary_inertia) * (0.5 * L)
            Jn[e, 0] = CA[e] @ Jsec @ CA[e].T
            Jn[e, 1] = CB[e] @ Jsec @ CB[e].T
            skind[e] = p.stress_kind
            spar[e] = p.stress_params
            beta[e] = float(s.damping)
        params = (length, eps0, Ks, beta, CA, CB, mass, cmix, Jn,
                  np.asarray(ctx.gravity, float), np.zeros(WORK_SIZE))
        g = make_group(self.name, specs, beam_kernel, params, lnodes, node_dofs(ctx, lnodes),
                       OUTPUTS, dissipative=True)
        g.extra["section_rotation"] = (CA, CB)
        g.derived = DerivedOutputs(cols=STRESS_COLUMNS, inputs=FORCE_COLUMNS,
                                   fn=partial(section_stresses, skind, spar))
        return g


register(BeamFamily())
