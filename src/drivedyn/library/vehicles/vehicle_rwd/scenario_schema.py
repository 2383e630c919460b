"""Schema of the RWD vehicle's scenario sections (``[scenarios.*]`` of the model file).

``[scenarios.power_on_cornering]``: the vehicle is built moving straight at ``speed``; the
pinion angle rises smoothly from 0 at ``steer_start`` to ``pinion_angle`` over
``steer_ramp`` and is held (a constant steer: the circle's radius follows from the
vehicle's response); a PI speed controller (:class:`~drivedyn.elements.SpeedController`,
the driver's foot) holds ``speed`` with the engine's torque; from ``throttle_start`` the
controller's output is held and a throttle ramp of ``throttle`` over ``throttle_ramp`` adds
to it (power on). The road's friction factor is ``road_mu`` under every wheel (the file's
``[road]`` friction and patches, set for the launch, are replaced). The engine runs in the
gear of ``gear_ratio`` (gearbox input over output speed). The controller's gains are in
throttle (the fraction of the full-load torque) per m/s of speed error (``kp`` [s/m]) and
per metre of integrated error (``ki`` [1/m]); ``initial_throttle`` is its integral term at
the start.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, model_validator

from drivedyn.library.differentials.schema_sections import PositiveTime, PositiveVelocity
from drivedyn.library.vehicles.vehicle_4wd.schema import Time
from drivedyn.schema_base import Angle, Strict, scalar

#: throttle per m/s [s/m] and per m [1/m]
ThrottlePerSpeed = Annotated[float, scalar((-1, 0, 1, 0), nonneg=True)]
ThrottlePerLength = Annotated[float, scalar((-1, 0, 0, 0), nonneg=True)]
Throttle = Annotated[float, Field(ge=0.0, le=1.0)]


class PowerOnCornering(Strict):
    """``[scenarios.power_on_cornering]`` (see the module docstring). Windows are
    ``[start, end]`` [s] over which the summaries average: ``steady_window`` before
    ``throttle_start`` (the steady circle), ``power_window`` after the throttle ramp has
    begun, both within ``t_end``."""

    speed: PositiveVelocity = 12.0
    road_mu: float = Field(default=1.0, gt=0.0)
    pinion_angle: Angle = -0.12
    steer_start: Time = 0.2
    steer_ramp: PositiveTime = 1.0
    gear_ratio: float = Field(default=1.607, gt=0.0)
    initial_throttle: Throttle = 0.08
    kp: ThrottlePerSpeed = 0.6
    ki: ThrottlePerLength = 0.45
    throttle_start: Time = 4.0
    throttle_ramp: PositiveTime = 1.0
    throttle: Throttle = 0.4
    t_end: PositiveTime = 6.0
    h_max: PositiveTime = 2e-3
    steady_window: tuple[Time, Time] = (3.0, 4.0)
    power_window: tuple[Time, Time] = (5.5, 6.0)

    @model_validator(mode="after")
    def _windows(self) -> PowerOnCornering:
        for key in ("steady_window", "power_window"):
            a, b = getattr(self, key)
            if not 0.0 <= a < b <= self.t_end:
                raise ValueError(f"{key} = {[a, b]} s: expected 0 <= start < end <= t_end = "
                                 f"{self.t_end:g} s")
        if self.steady_window[1] > self.throttle_start + 1e-12:
            raise ValueError(f"steady_window = {list(self.steady_window)} s ends after "
                             f"throttle_start = {self.throttle_start:g} s: the steady circle is "
                             "the part before the throttle ramp")
        if self.power_window[0] < self.throttle_start:
            raise ValueError(f"power_window = {list(self.power_window)} s starts before "
                             f"throttle_start = {self.throttle_start:g} s")
        if self.steer_start + self.steer_ramp > self.steady_window[0]:
            raise ValueError(f"steer_start + steer_ramp = "
                             f"{self.steer_start + self.steer_ramp:g} s is after the "
                             f"steady_window's start {self.steady_window[0]:g} s")
        return self


class Scenarios(Strict):
    """The scenarios' own parameters."""

    power_on_cornering: PowerOnCornering = Field(default_factory=PowerOnCornering)
