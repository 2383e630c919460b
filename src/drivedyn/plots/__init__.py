"""Figures drawn from results (PNG through the Agg canvas, no display needed).

* :mod:`~drivedyn.plots.vehicle`: the TORSEN Type C vehicle configuration figures;
* :mod:`~drivedyn.plots.beams`: stress histories of beam elements and snapshots of the
  deformed beams.
"""

from drivedyn.plots.beams import beam_shape_figure, beam_stress_figure
from drivedyn.plots.vehicle import vehicle_figures

__all__ = ["beam_shape_figure", "beam_stress_figure", "vehicle_figures"]
