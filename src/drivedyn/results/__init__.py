"""Recording, results (xarray Dataset) and results files."""

from drivedyn.results.results import Results, load_results, write_netcdf_atomic

__all__ = ["Results", "load_results", "write_netcdf_atomic"]
