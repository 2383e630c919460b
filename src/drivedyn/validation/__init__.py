"""Validation cases run by ``drivedyn validate``: each compares a simulated quantity with an
exact or published reference."""

from drivedyn.validation.base import CASES, CaseResult, compare, register_case, run_cases

__all__ = ["CASES", "CaseResult", "compare", "register_case", "run_cases"]
