"""The named configurations of the 4WD vehicle: which differential type sits at each of the
three positions (central, front, rear). ``drivedyn vehicle --compare`` runs them side by
side; a run's results record the name of its configuration."""

from __future__ import annotations

from drivedyn.library.vehicles.vehicle_4wd.schema import Vehicle4WDFile

#: configuration name -> differential types at (central, front, rear)
CONFIGS = {
    "open": ("open", "open", "open"),
    "locked": ("locked", "locked", "locked"),
    "clutch": ("clutch", "clutch", "clutch"),
    "torsen": ("torsen-c", "torsen-b", "torsen-b"),
}


def config_name(types: dict[str, str] | Vehicle4WDFile) -> str:
    """The :data:`CONFIGS` key of a set of position types (a dict or the parameters), or
    ``"central/front/rear"`` types when it is none of them."""
    if isinstance(types, Vehicle4WDFile):
        d = types.differentials
        types = {"central": d.central, "front": d.front, "rear": d.rear}
    key = tuple(types[p] for p in ("central", "front", "rear"))
    for k, v in CONFIGS.items():
        if key == v:
            return k
    return "/".join(key)
