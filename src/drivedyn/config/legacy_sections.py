"""The dedicated element sections of older model files, read as deprecated aliases of
``[[elements]]``: ``[[joints]]`` (``type = "hinge"``...), ``[[springs]]``,
``[[torsional_springs]]``, ``[[forces]]``, ``[[torques]]``, ``[[drivers]]`` and
``[[speed_difference_drivers]]``.

Each of their entries becomes an ``[[elements]]`` entry whose ``type`` is the element's class
name, ahead of the file's own ``[[elements]]`` entries and section by section in the order of
:data:`SECTIONS` (the order these sections always had in the model, which decides the order of
the element groups and so the results). Their keys are the element's constructor parameters,
except a joint's lowercase ``type`` (mapped to its class name, and ``pitch`` only for a screw);
every parameter is then checked by the ``[[elements]]`` path against its element class, where
it is declared once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from drivedyn.config.elements_section import element_types
from drivedyn.errors import did_you_mean

#: deprecated section -> element class name of its entries (joints: by their ``type``), in
#: the order their elements enter the model
SECTIONS: dict[str, str | None] = {
    "joints": None,
    "springs": "SpringDamper",
    "torsional_springs": "TorsionalSpringDamper",
    "forces": "Force",
    "torques": "Torque",
    "drivers": "JointDriver",
    "speed_difference_drivers": "SpeedDifferenceDriver",
}


def joint_types() -> dict[str, str]:
    """Lowercase ``type`` of a ``[[joints]]`` entry (``"hinge"``) -> joint class name
    (``"Hinge"``), from each joint class's ``kind``."""
    from drivedyn.elements.joints import Joint

    return {cls.kind: name for name, cls in element_types().items()
            if issubclass(cls, Joint) and cls.kind}


@dataclass
class Translation:
    """A plain model file's data with its deprecated sections translated."""

    #: the data, the deprecated sections' entries moved into ``elements``
    data: dict[str, Any]
    #: how messages name each ``elements`` entry: ``"elements[0] (mesh)"`` for the file's own,
    #: ``"joints[1] (hinge)"`` for a translated one
    labels: list[str] = field(default_factory=list)
    #: ``"key.path: what is wrong"`` for each entry that cannot be translated
    problems: list[str] = field(default_factory=list)
    #: deprecated section used -> the class names its entries became (file order)
    used: dict[str, list[str]] = field(default_factory=dict)

    def notes(self, source: str) -> list[str]:
        """One deprecation message per deprecated section used: the section, the file and
        the syntax that replaces it."""
        out = []
        for section, classes in self.used.items():
            names = " or ".join(f'"{c}"' for c in dict.fromkeys(classes)) or '"Hinge"'
            out.append(f"model file {source}: [[{section}]] is deprecated; write [[elements]] "
                       f"with type = {names} (the element's class name)")
        return out


def _label(section: str, i: int, item: Any) -> str:
    name = item.get("name") if isinstance(item, dict) else None
    return f"{section}[{i}]" + (f" ({name})" if isinstance(name, str) and name else "")


def entry_class(section: str, item: Any) -> str | None:
    """The element class name an entry of ``section`` (``elements`` or a deprecated one)
    stands for, or None if it names none."""
    if not isinstance(item, dict):
        return None
    if section == "elements":
        t = item.get("type")
        return t if isinstance(t, str) else None
    if section == "joints":
        t = item.get("type")
        return joint_types().get(t) if isinstance(t, str) else None
    return SECTIONS.get(section)


def translate(data: dict[str, Any]) -> Translation:
    """``data`` (not changed) with the entries of the deprecated sections as ``[[elements]]``
    entries ahead of the file's own; keys that cannot map are problems naming the key."""
    if not any(s in data for s in SECTIONS):
        own = data.get("elements")
        return Translation(data, [_label("elements", i, it) for i, it in
                                  enumerate(own if isinstance(own, list) else [])])
    out = {k: v for k, v in data.items() if k not in SECTIONS}
    tr = Translation(out)
    entries: list[Any] = []
    joints = joint_types()
    for section, cls in SECTIONS.items():
        if section not in data:
            continue
        items = data[section]
        if not isinstance(items, list):
            tr.problems.append(
                f"{section}: expected a list of [[{section}]] tables, got {items!r}"
                + (" (the file's elements are in [[elements]]: set elements.NAME.KEY)"
                   if isinstance(items, dict) else ""))
            continue
        tr.used[section] = []
        for i, item in enumerate(items):
            label = _label(section, i, item)
            if not isinstance(item, dict):
                tr.problems.append(f"{label}: expected a table of the element's keys, got "
                                   f"{item!r}")
                continue
            entry = dict(item)
            if cls is None:  # a joint: its class by its type
                name = _joint_class(entry, label, joints, tr.problems)
                if name is None:
                    continue
            elif "type" in entry:
                tr.problems.append(f"{label}.type: unknown key ([[{section}]] entries are "
                                   f"{cls} elements; [[elements]] takes type = \"{cls}\")")
                continue
            else:
                name = cls
            tr.used[section].append(name)
            entries.append({"type": name, **entry})
            tr.labels.append(label)
    own = data.get("elements", [])
    if not isinstance(own, list):
        tr.problems.append(f"elements: expected a list of [[elements]] tables, got {own!r}")
        own = []
    out["elements"] = entries + own
    tr.labels += [_label("elements", i, it) for i, it in enumerate(own)]
    return tr


def _joint_class(entry: dict, label: str, joints: dict[str, str],
                 problems: list[str]) -> str | None:
    """The class name of a ``[[joints]]`` entry (its ``type`` and, for a screw, ``pitch``
    checked; ``type`` removed from ``entry``), or None after adding a problem."""
    kinds = ", ".join(joints)
    if "type" not in entry:
        problems.append(f"{label}.type: required key is missing (one of {kinds})")
        return None
    kind = entry.pop("type")
    cls = joints.get(kind) if isinstance(kind, str) else None
    if cls is None:
        hint = did_you_mean(kind, joints) if isinstance(kind, str) else ""
        problems.append(f"{label}.type: unknown joint type {kind!r}{hint} (expected one of "
                        f"{kinds})")
        return None
    if kind == "screw" and "pitch" not in entry:
        problems.append(f"{label}.pitch: required key is missing (a screw joint's advance "
                        "per revolution [m])")
        return None
    if kind != "screw" and "pitch" in entry:
        problems.append(f"{label}.pitch: only a screw joint takes a pitch (got "
                        f"{entry['pitch']!r} on a {kind} joint)")
        return None
    return cls
