"""The element framework: what every element family builds on, apart from the families.

* :mod:`~drivedyn.elements.framework.contract`: the kernel contract (calling convention,
  evaluation modes, scatter of the local residual and matrices).
* :mod:`~drivedyn.elements.framework.group`: the :class:`Group` of a family's elements in a
  compiled model, its outputs and its commit.
* :mod:`~drivedyn.elements.framework.registry`: element specs, :class:`Family` and the
  registry of families.
* :mod:`~drivedyn.elements.framework.scaffold`: the kernel scaffold (dispatch, common
  arguments, scatter and outputs).
* :mod:`~drivedyn.elements.framework.building`: marker lookup, index maps and the group of a
  family's specs.
* :mod:`~drivedyn.elements.framework.checks`: checks of element parameters.
* :mod:`~drivedyn.elements.framework.work_arrays`: work arrays carved from one buffer.
* :mod:`~drivedyn.elements.framework.primitives`: kinematic primitives (numba) shared by
  joints, drivers and force elements.
* :mod:`~drivedyn.elements.framework.visuals`: the shapes an element declares to the viewer.

Nothing here imports a family.
"""
