"""drivedyn: flexible multibody simulation of automotive drivelines.

Build a :class:`Spec`, ``compile_model`` it, ``simulate`` it::

    import drivedyn as dd
    spec = dd.Spec(gravity=(0, 0, -9.81))
    ...
    results = dd.simulate(dd.compile_model(spec), t_end=1.0)
"""

import importlib
from typing import Any

# public names -> defining module, imported on first use (PEP 562): `import drivedyn` and
# the command line stay fast (`drivedyn --help` must not load numba and the kernels)
_EXPORTS: dict[str, str] = {
    "AdaptiveStep": "drivedyn.solver",
    "Bushing": "drivedyn.elements",
    "BushingCurve": "drivedyn.elements",
    "BushingRotationalCurve": "drivedyn.elements",
    "BumpStop": "drivedyn.elements",
    "Constant": "drivedyn.timefunctions",
    "configure": "drivedyn.settings",
    "Cylindrical": "drivedyn.elements",
    "Fixed": "drivedyn.elements",
    "FixedStep": "drivedyn.solver",
    "FlexibleBody": "drivedyn.elements.flexible",
    "FlexibleInterface": "drivedyn.elements.flexible",
    "FlexibleWasherContact": "drivedyn.elements.flexible",
    "Force": "drivedyn.elements",
    "FrictionLaw": "drivedyn.elements",
    "GROUND": "drivedyn.model",
    "GearPair": "drivedyn.elements",
    "GeneralSection": "drivedyn.elements.beams",
    "GeneralizedAlpha": "drivedyn.solver",
    "GeometricallyExactBeam": "drivedyn.elements.beams",
    "Hinge": "drivedyn.elements",
    "HollowCircular": "drivedyn.elements.beams",
    "JointDriver": "drivedyn.elements",
    "JournalContact": "drivedyn.elements",
    "JournalFilm": "drivedyn.elements",
    "Material": "drivedyn.elements.beams",
    "MaxwellBranch": "drivedyn.elements",
    "Model": "drivedyn.model",
    "ModelError": "drivedyn.model",
    "ModelFileError": "drivedyn.config",
    "Newton": "drivedyn.solver",
    "NonlinearSpringDamper": "drivedyn.elements",
    "NormalLaw": "drivedyn.elements",
    "ParallelAxes": "drivedyn.elements",
    "Planar": "drivedyn.elements",
    "PlaneContact": "drivedyn.elements",
    "Prismatic": "drivedyn.elements",
    "Ramp": "drivedyn.timefunctions",
    "Rectangular": "drivedyn.elements.beams",
    "Results": "drivedyn.results",
    "STEEL": "drivedyn.elements.beams",
    "Screw": "drivedyn.elements",
    "SmoothStep": "drivedyn.timefunctions",
    "SolidCircular": "drivedyn.elements.beams",
    "Spec": "drivedyn.model",
    "SpeedDifferenceDriver": "drivedyn.elements",
    "Spherical": "drivedyn.elements",
    "SpringDamper": "drivedyn.elements",
    "SqueezeFilm": "drivedyn.elements",
    "State": "drivedyn.model",
    "Table": "drivedyn.timefunctions",
    "ThrustWasherContact": "drivedyn.elements",
    "Torque": "drivedyn.elements",
    "TyreContact": "drivedyn.elements",
    "RoadPatch": "drivedyn.elements",
    "RotationalMaxwellBranch": "drivedyn.elements",
    "read_tir": "drivedyn.tyres",
    "simple_tyre": "drivedyn.tyres",
    "TorsionalSpringDamper": "drivedyn.elements",
    "UnilateralContact": "drivedyn.elements",
    "Universal": "drivedyn.elements",
    "add_flexible_body": "drivedyn.model.flexible",
    "add_straight_beam": "drivedyn.model.beams",
    "compile_model": "drivedyn.model",
    "dashboard_figures": "drivedyn.plots",
    "element_outputs": "drivedyn.solver",
    "engineering_figures": "drivedyn.plots",
    "linear_modes": "drivedyn.solver",
    "load_model": "drivedyn.config",
    "load_results": "drivedyn.results",
    "plot_quantities": "drivedyn.plots",
    "simulate": "drivedyn.solver",
    "solve_static": "drivedyn.solver",
    "sweep": "drivedyn.sweeps",
}

__version__ = "0.1.0"

__all__ = [
    "GROUND",
    "STEEL",
    "AdaptiveStep",
    "BumpStop",
    "Bushing",
    "BushingCurve",
    "BushingRotationalCurve",
    "Constant",
    "Cylindrical",
    "Fixed",
    "FixedStep",
    "FlexibleBody",
    "FlexibleInterface",
    "FlexibleWasherContact",
    "Force",
    "FrictionLaw",
    "GearPair",
    "GeneralSection",
    "GeneralizedAlpha",
    "GeometricallyExactBeam",
    "Hinge",
    "HollowCircular",
    "JointDriver",
    "JournalContact",
    "JournalFilm",
    "Material",
    "MaxwellBranch",
    "Model",
    "ModelError",
    "ModelFileError",
    "Newton",
    "NonlinearSpringDamper",
    "NormalLaw",
    "ParallelAxes",
    "Planar",
    "PlaneContact",
    "Prismatic",
    "Ramp",
    "Rectangular",
    "Results",
    "RotationalMaxwellBranch",
    "Screw",
    "SmoothStep",
    "SolidCircular",
    "Spec",
    "SpeedDifferenceDriver",
    "Spherical",
    "SpringDamper",
    "SqueezeFilm",
    "State",
    "Table",
    "ThrustWasherContact",
    "Torque",
    "TorsionalSpringDamper",
    "UnilateralContact",
    "Universal",
    "add_flexible_body",
    "add_straight_beam",
    "compile_model",
    "configure",
    "dashboard_figures",
    "element_outputs",
    "engineering_figures",
    "linear_modes",
    "load_model",
    "load_results",
    "plot_quantities",
    "simulate",
    "solve_static",
    "sweep",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'drivedyn' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
