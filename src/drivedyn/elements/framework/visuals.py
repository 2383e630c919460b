"""Visual shapes: what an element or a library model looks like in the 3-D viewer.

A :class:`Visual` is data only (no drawing code): a shape kind, its dimensions [m] and a
role (gear, shaft, washer, case...), attached to a **marker**. The shape's axis is the
marker's z axis and its centre the marker's origin, so the shape moves with the body, node
or ground the marker sits on. Element specs declare their shapes through
``ElementSpec.visuals()`` (a gear pair: its two wheels; a thrust washer: an annulus; a tyre:
its wheel); library models add the shapes of their bodies (cases, shafts) with
``Spec.add_visual``. Bodies that nothing draws are shown as the box of equal mass and
inertia (:mod:`drivedyn.results.scene`). The viewer turns these records into triangle
meshes (:mod:`drivedyn.viewer.meshes`).

Kinds and their parameters (all lengths in metres, angles in radians):

- ``"cylinder"``: ``radius``, ``length``, ``inner_radius`` (0: solid; > 0: tube, washer),
  ``radius_end`` (the radius at +z: a cone frustum), ``z0`` (the start along z; default
  ``-length/2``: centred on the marker), ``relative`` (1: the lengths are fractions of the
  mechanism's size, the largest spread of its nodes at the start: a bushing drawn to the
  scale of whatever it sits in).
- ``"gear"``: ``teeth``, ``pitch_radius``, ``face_width``, ``module`` (normal),
  ``helix_angle`` (signed: right hand > 0), ``internal`` (1: a ring gear, teeth inward),
  ``cone_angle`` (bevel: pitch cone half-angle; 0: cylindrical).
- ``"box"``: ``sx``, ``sy``, ``sz`` (edge lengths along the marker's x, y, z).
- ``"sphere"``: ``radius``.
- ``"axes"``: ``length``: the marker's frame as three arrows (joint axes; drawn on request).
- ``"arrow"``: no parameters: an arrow along the marker's z axis whose length follows
  ``variable`` (a scalar results variable, e.g. a washer's normal force); the viewer uses one
  force scale for all arrows, so that their lengths compare.
- ``"point_force"``: ``reach`` [m], ``radial`` (0 or 1): a force arrow at the point at
  distance ``reach`` from the marker's origin towards ``marker_b``'s origin (in the plane
  normal to the marker's z axis; a negative reach points away from it): a gear mesh's pitch
  point, a pin's contact point in its bore. ``radial = 0``: the force is the global vector
  ``variable_x, _y, _z``; ``radial = 1``: it is ``variable`` (a scalar) along the line from
  ``marker_b`` towards the marker (the bore pushing the pin back).
- ``"link"``: ``radius``: a tube from the marker's origin to ``marker_b``'s origin, redrawn
  at every frame (a shaft between two bodies: a half-shaft from its differential output to
  the wheel hub, a damper); radius 0: a twentieth of the markers' initial distance.
  ``fraction`` (optional): only a stub of that fraction of the initial distance from the
  marker towards ``marker_b`` (a bump stop's rubber; radius 0: 0.08 of the distance).
- ``"coil"``: ``radius`` (of the coil; 0: 0.15 of the markers' initial distance),
  ``turns``, ``wire`` (the wire's radius; 0: 0.12 of the coil's): a helical coil spring from
  the marker's origin to ``marker_b``'s, stretched with them at every frame.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

KINDS = ("cylinder", "gear", "box", "sphere", "axes", "arrow", "point_force", "link", "coil")
ROLES = ("gear", "shaft", "washer", "case", "housing", "body", "wheel", "joint", "force",
         "chassis", "pin", "part", "spring", "damper", "stop", "bushing")


@dataclass(frozen=True)
class Visual:
    """One shape on a marker (see the module docstring for kinds and parameters).

    Attributes:
        marker: name of the marker carrying the shape (z = shape axis).
        kind: one of :data:`KINDS`.
        role: what the shape is (one of :data:`ROLES`): sets the default colour, and cases
            and housings are drawn semi-transparent.
        params: the kind's dimensions as ``(name, value)`` pairs, SI units.
        label: what the viewer shows on hover (the element or body name by default).
        variable: results variable driving an ``"arrow"`` or ``"point_force"`` (empty for
            the other kinds).
        opacity: 0..1; None chooses from the role.
        marker_b: the second marker of a ``"point_force"`` or a ``"link"``.
    """

    marker: str
    kind: str
    role: str
    params: tuple[tuple[str, float], ...] = ()
    label: str = ""
    variable: str = ""
    opacity: float | None = None
    marker_b: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"visual on {self.marker!r}: kind {self.kind!r} is not one of "
                             f"{', '.join(KINDS)}")
        if self.role not in ROLES:
            raise ValueError(f"visual on {self.marker!r}: role {self.role!r} is not one of "
                             f"{', '.join(ROLES)}")

    @property
    def values(self) -> dict[str, float]:
        return dict(self.params)

    def renamed(self, names: dict[str, str]) -> Visual:
        """The same shape with its marker (and variable prefix) renamed (sub-assemblies)."""
        var = self.variable
        if var and "." in var:
            head, tail = var.split(".", 1)
            var = names.get(head, head) + "." + tail
        return replace(self, marker=names.get(self.marker, self.marker), variable=var,
                       label=names.get(self.label, self.label),
                       marker_b=names.get(self.marker_b, self.marker_b))

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready description (stored in results files)."""
        out: dict[str, Any] = {"kind": self.kind, "role": self.role, "label": self.label,
                               "params": {k: float(v) for k, v in self.params}}
        if self.variable:
            out["variable"] = self.variable
        if self.opacity is not None:
            out["opacity"] = float(self.opacity)
        return out


def _params(**kw: float | None) -> tuple[tuple[str, float], ...]:
    return tuple((k, float(v)) for k, v in kw.items() if v is not None)


def cylinder(marker: str, radius: float, length: float, *, role: str = "shaft",
             inner_radius: float = 0.0, radius_end: float | None = None,
             z0: float | None = None, label: str = "", opacity: float | None = None,
             relative: bool = False) -> Visual:
    """A solid or hollow cylinder (or cone frustum) along the marker's z axis [m]; with
    ``relative`` the lengths are fractions of the mechanism's size."""
    return Visual(marker, "cylinder", role,
                  _params(radius=radius, length=length, inner_radius=inner_radius,
                          radius_end=radius_end, z0=z0, relative=1.0 if relative else None),
                  label=label, opacity=opacity)


def gear(marker: str, teeth: int, pitch_radius: float, face_width: float, module: float, *,
         helix_angle: float = 0.0, internal: bool = False, cone_angle: float = 0.0,
         label: str = "") -> Visual:
    """A toothed wheel centred on the marker, axis = marker z [m, rad]."""
    return Visual(marker, "gear", "gear",
                  _params(teeth=teeth, pitch_radius=pitch_radius, face_width=face_width,
                          module=module, helix_angle=helix_angle, internal=float(internal),
                          cone_angle=cone_angle), label=label)


def box(marker: str, sx: float, sy: float, sz: float, *, role: str = "body",
        label: str = "", opacity: float | None = None) -> Visual:
    """A box centred on the marker, edges along its axes [m]."""
    return Visual(marker, "box", role, _params(sx=sx, sy=sy, sz=sz), label=label,
                  opacity=opacity)


def sphere(marker: str, radius: float, *, role: str = "body", label: str = "") -> Visual:
    """A sphere centred on the marker [m]."""
    return Visual(marker, "sphere", role, _params(radius=radius), label=label)


def axes(marker: str, length: float, *, label: str = "") -> Visual:
    """The marker's frame as three arrows of ``length`` [m] (joint axes; on request)."""
    return Visual(marker, "axes", "joint", _params(length=length), label=label)


def arrow(marker: str, variable: str, *, label: str = "") -> Visual:
    """An arrow along the marker's z axis whose length follows the results variable
    ``variable`` (a contact's normal force [N]; positive: along +z)."""
    return Visual(marker, "arrow", "force", label=label, variable=variable)


def point_force(marker: str, marker_b: str, variable: str, reach: float, *,
                radial: bool = False, label: str = "") -> Visual:
    """A force arrow at ``reach`` [m] from ``marker`` towards ``marker_b`` (see the module
    docstring): a mesh force (``variable`` + ``_x/_y/_z``, global) or a radial contact force
    (``radial``: the scalar ``variable`` [N] pushing ``marker_b`` back towards the axis)."""
    return Visual(marker, "point_force", "force", _params(reach=reach, radial=float(radial)),
                  label=label, variable=variable, marker_b=marker_b)


def link(marker: str, marker_b: str, radius: float, *, role: str = "shaft",
         label: str = "", fraction: float | None = None) -> Visual:
    """A tube of ``radius`` [m] (0: sized by the viewer) from the origin of ``marker`` to the
    origin of ``marker_b``, following both at every frame (a shaft joining two bodies); with
    ``fraction`` only a stub of that fraction of their initial distance from ``marker``."""
    return Visual(marker, "link", role, _params(radius=radius, fraction=fraction), label=label,
                  marker_b=marker_b)


def coil(marker: str, marker_b: str, radius: float = 0.0, *, turns: float = 7.0,
         wire: float = 0.0, role: str = "spring", label: str = "") -> Visual:
    """A helical coil spring of ``radius`` [m] with ``turns`` turns of a wire of radius
    ``wire`` [m] (0: sized by the viewer from the markers' initial distance) between the
    origins of ``marker`` and ``marker_b``, stretched with them at every frame."""
    return Visual(marker, "coil", role, _params(radius=radius, turns=turns, wire=wire),
                  label=label, marker_b=marker_b)
