"""Recording, results (xarray Dataset) and results files."""

from drivedyn.results.results import Results, RunStats, load_results, write_netcdf_atomic

__all__ = ["Results", "RunStats", "load_results", "write_netcdf_atomic"]
