"""The run report: one HTML page that sums up a results file (:mod:`.run_report`)."""

from drivedyn.report.run_report import SECTIONS, write_report

__all__ = ["SECTIONS", "write_report"]
