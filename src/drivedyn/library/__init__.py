"""Model library: parametric assemblies built on the element families (benchmarks, test
benches, differentials). Each module builds a :class:`~drivedyn.model.spec.Spec` or a
compiled model from a few physical parameters and, where useful, runs and post-processes it."""
