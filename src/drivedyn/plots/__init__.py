"""Figures drawn from results (PNG through the Agg canvas, no display needed).

* :mod:`~drivedyn.plots.engineering`: what ``drivedyn plot`` draws for any run (the
  engineering quantities in units with SI prefixes, :mod:`~drivedyn.plots.quantities`) and the
  dashboard of a library model (:mod:`~drivedyn.plots.dashboard`);
* :mod:`~drivedyn.plots.vehicle`: the TORSEN Type C vehicle configuration figures;
* :mod:`~drivedyn.plots.beams`: stress histories of beam elements and snapshots of the
  deformed beams.
"""

from drivedyn.plots.beams import beam_shape_figure, beam_stress_figure
from drivedyn.plots.engineering import dashboard_figures, engineering_figures, plot_quantities
from drivedyn.plots.vehicle import vehicle_figures

__all__ = ["beam_shape_figure", "beam_stress_figure", "dashboard_figures",
           "engineering_figures", "plot_quantities", "vehicle_figures"]
