"""Spec (editable description) -> compile -> Model (frozen) + State (mutable)."""

from drivedyn.model.compile import compile_model
from drivedyn.model.model import Model, State
from drivedyn.model.spec import GROUND, ModelError, Spec

__all__ = ["GROUND", "Model", "ModelError", "Spec", "State", "compile_model"]
