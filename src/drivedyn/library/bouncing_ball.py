"""The seeds' bouncing-ball benchmark of continuous impact (seeds 000, 001; physics.md 3).

A ball of mass ``m`` falls from the height ``h0`` under gravity ``g`` onto a rigid floor and
bounces; the contact is a :class:`~drivedyn.elements.contact.PlaneContact` (point on plane)
with a continuous-impact :class:`~drivedyn.elements.contact.impact_laws.NormalLaw`
``F = K delta^n [1 + chi deltadot / v_s]``. The seeds' values: e = 0.8, n = 1.5,
K = 1e10 N/m^1.5, h0 = 1 m, m = 0.85 kg, g = 10 m/s^2 (Lankarani-Nikravesh law).

:func:`run_bounce` simulates it with an adaptive step (the contact lasts about 0.2 ms at the
first impact; steps of a few microseconds resolve it, free flight takes steps up to the output
interval) and extracts per bounce the approach and rebound speeds at ``delta = 0`` (from the
contact's state outputs), the achieved restitution (rebound over approach speed) and the apex
height of the following flight. The prediction of the exact restitution relation for the
law's damping factor is :func:`~drivedyn.elements.contact.impact_laws.restitution_from_chi`.

The ball is a point at its lowest point (the contact point); "height" is the height of that
point above the floor. Its inertia is that of a 30 mm sphere (it does not rotate).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drivedyn.elements.contact import PlaneContact
from drivedyn.elements.contact.impact_laws import IMPACT_LAWS, NormalLaw, restitution_from_chi
from drivedyn.model.compile import compile_model
from drivedyn.model.model import Model
from drivedyn.model.spec import GROUND, Spec
from drivedyn.solver.settings import AdaptiveStep, GeneralizedAlpha
from drivedyn.solver.simulate import simulate

SEED_PARAMETERS = {"law": "lankarani-nikravesh", "e": 0.8, "n": 1.5, "k": 1e10, "mass": 0.85,
                   "h0": 1.0, "gravity": 10.0}
"""The seeds' benchmark (seed 000): restitution, exponent, stiffness [N/m^1.5], mass [kg],
drop height [m], gravity [m/s^2]."""

BALL_RADIUS = 0.03  # [m], only for the inertia
CONTACT = "floor_contact"


def bouncing_ball_spec(law: str = "lankarani-nikravesh", e: float = 0.8, n: float = 1.5,
                       k: float = 1e10, mass: float = 0.85, h0: float = 1.0,
                       gravity: float = 10.0, v0: float = 0.0,
                       min_impact_speed: float = 1e-4) -> Spec:
    """The ball (body ``"ball"``) at height ``h0`` [m] with downward speed ``v0`` [m/s] above
    the floor (plane z = 0, normal +z), gravity ``-gravity`` along z, contact ``"floor_contact"``
    with the normal law ``law`` (restitution ``e``, exponent ``n``, stiffness ``k``)."""
    spec = Spec(gravity=(0.0, 0.0, -float(gravity)))
    j = 0.4 * mass * BALL_RADIUS**2
    spec.add_rigid_body("ball", mass, (j, j, j), position=(0.0, 0.0, h0),
                        velocity=(0.0, 0.0, -v0))
    spec.add_marker("floor", GROUND)
    spec.add_marker("ball_bottom", "ball")
    spec.add(PlaneContact(CONTACT, "floor", "ball_bottom",
                          law=NormalLaw(stiffness=k, exponent=n, law=law, restitution=e,
                                        min_impact_speed=min_impact_speed)))
    return spec


def bouncing_ball_model(**kwargs: Any) -> Model:
    """The compiled model of :func:`bouncing_ball_spec` (same keyword arguments)."""
    return compile_model(bouncing_ball_spec(**kwargs))


def default_step(rtol: float = 1e-6, atol: float = 1e-12) -> AdaptiveStep:
    """The step control of the benchmark: starts at 0.1 ms, between 1e-9 s (Newton failures and
    the error estimate at contact onset shrink it) and 10 ms; ``rtol`` relative accuracy of
    the motion within a step, ``atol`` [m] absolute.

    The defaults resolve the first impact (0.2 ms, peak penetration 0.34 mm) with about 250
    steps. They are set by the contact onset: the force kink at ``delta = 0`` costs the
    integrator a velocity error of order ``h a`` in the step where the contact starts, which
    the position error estimate only sees through ``atol``; with rtol = 1e-6, atol = 1e-12
    the achieved restitution matches an exact reference to 5e-7 (1e-4 / 1e-9: 1e-4).
    """
    return AdaptiveStep(h0=1e-4, h_min=1e-9, h_max=1e-2, rtol=rtol, atol=atol,
                        max_rejections=40)


@dataclass
class BounceRun:
    """A simulated bouncing ball and what was measured.

    Attributes:
        law, e_target: the normal law and the restitution it was given.
        chi: its damping factor; e_predicted: the restitution the exact relation predicts.
        impact_speeds, rebound_speeds: per completed bounce, approach and separation speed at
            delta = 0 [m/s].
        restitution: per completed bounce, rebound over approach speed.
        apex_heights: apex of the flight after each bounce [m] (completed flights only).
        apex_times: times of those apexes [s].
        steps, rejected, wall_s: solver statistics of the run.
        energy_balance_error: max |(T + V) - (T0 + V0) + D| over the run [J].
        dissipated: energy dissipated by the contact at the end [J].
        results: the :class:`~drivedyn.results.results.Results`.
    """

    law: str
    e_target: float
    chi: float
    e_predicted: float
    impact_speeds: list[float]
    rebound_speeds: list[float]
    restitution: list[float]
    apex_heights: list[float]
    apex_times: list[float]
    steps: int
    rejected: int
    wall_s: float
    energy_balance_error: float
    dissipated: float
    success: bool
    message: str
    results: Any = field(repr=False, default=None)

    def as_dict(self) -> dict[str, Any]:
        """The JSON object of ``drivedyn bounce --json``."""
        return {
            "law": self.law, "e_target": self.e_target, "chi": self.chi,
            "e_predicted": self.e_predicted, "apex_heights": self.apex_heights,
            "apex_times": self.apex_times, "restitution": self.restitution,
            "impact_speeds": self.impact_speeds, "rebound_speeds": self.rebound_speeds,
            "steps": self.steps, "rejected_steps": self.rejected, "wall_s": self.wall_s,
            "energy_balance_error": self.energy_balance_error,
            "dissipated_energy": self.dissipated, "success": self.success,
            "message": self.message,
        }


def _apex(t: np.ndarray, z: np.ndarray) -> tuple[float, float]:
    """Apex time and height of a sampled parabola (vertex through the largest sample and its
    neighbours; exact for free flight)."""
    i = int(np.argmax(z))
    if i == 0 or i == len(z) - 1:
        return float(t[i]), float(z[i])
    t0, t1, t2 = t[i - 1], t[i], t[i + 1]
    c = np.polyfit([t0 - t1, 0.0, t2 - t1], [z[i - 1], z[i], z[i + 1]], 2)
    if c[0] >= 0.0:
        return float(t1), float(z[i])
    tv = -c[1] / (2.0 * c[0])
    return float(t1 + tv), float(np.polyval(c, tv))


def bounces(results: Any, contact: str = CONTACT, body: str = "ball") -> dict[str, list[float]]:
    """Per-bounce speeds, restitution and apex heights from a run's outputs.

    A bounce ``k`` starts at the first output where the contact's ``impacts`` counter reaches
    ``k``; its approach speed is the contact's ``impact_speed`` there, its rebound speed the
    ``rebound_speed`` at the last output before the next impact if the ball is in the air
    there. The apex of the flight after it is the vertex of the sampled height (taken only if
    the flight reaches its apex before the next impact and the end of the run).
    """
    t = results.time
    z = results[f"{body}.position"].values[:, 2]
    cnt = np.rint(results[f"{contact}.impacts"].values).astype(int)
    vin = results[f"{contact}.impact_speed"].values
    vout = results[f"{contact}.rebound_speed"].values
    inside = results[f"{contact}.in_contact"].values > 0.5
    out: dict[str, list[float]] = {"impact_speeds": [], "rebound_speeds": [],
                                   "restitution": [], "apex_heights": [], "apex_times": []}
    starts = [int(np.argmax(cnt >= k)) for k in range(1, int(cnt.max(initial=0)) + 1)]
    for j, i0 in enumerate(starts):
        i1 = starts[j + 1] if j + 1 < len(starts) else len(t)
        last = i1 - 1
        if last <= i0 or inside[last] or cnt[last] != j + 1:
            break
        out["impact_speeds"].append(float(vin[i0]))
        out["rebound_speeds"].append(float(vout[last]))
        out["restitution"].append(float(vout[last] / vin[i0]))
        seg = slice(i0, i1)
        ta, za = _apex(t[seg], z[seg])
        k = int(np.argmax(z[seg]))
        if 0 < k < i1 - i0 - 1 and not inside[i0 + k]:
            out["apex_heights"].append(za)
            out["apex_times"].append(ta)
    return out


def run_bounce(law: str = "lankarani-nikravesh", e: float = 0.8, n: float = 1.5,
               k: float = 1e10, mass: float = 0.85, h0: float = 1.0, gravity: float = 10.0,
               t_end: float = 3.0, v0: float = 0.0, rho_inf: float = 1.0,
               step: AdaptiveStep | None = None, output_dt: float = 2e-3) -> BounceRun:
    """Simulate the bouncing ball for ``t_end`` [s] and measure its bounces.

    ``rho_inf = 1`` (no numerical dissipation: the energy lost is the contact's alone);
    ``output_dt`` [s] sets the sampling of the height (apexes are refined by the vertex of a
    parabola, exact for free flight). See :func:`bouncing_ball_spec` for the parameters.
    """
    if law not in IMPACT_LAWS:
        raise ValueError(f"unknown impact law {law!r} (known: {', '.join(IMPACT_LAWS)})")
    model = bouncing_ball_model(law=law, e=e, n=n, k=k, mass=mass, h0=h0, gravity=gravity,
                                v0=v0)
    res = simulate(model, t_end, integrator=GeneralizedAlpha(rho_inf),
                   step=step or default_step(), output_dt=output_dt)
    b = bounces(res)
    chi = model.spec.element(CONTACT).law.chi
    bal = res["energy.balance_error"].values
    return BounceRun(
        law=law, e_target=float(e), chi=float(chi), e_predicted=restitution_from_chi(chi),
        steps=res.stats.steps, rejected=res.stats.rejected, wall_s=res.stats.wall_s,
        energy_balance_error=float(np.max(np.abs(bal))) if bal.size else 0.0,
        dissipated=float(res[f"{CONTACT}.dissipated_energy"].values[-1]),
        success=res.success, message=res.message, results=res, **b,
    )


def plot_height(run: BounceRun, fig: Any) -> None:
    """Draw height against time (the seeds' figure) into a matplotlib figure."""
    res = run.results
    ax = fig.subplots()
    ax.plot(res.time, res["ball.position"].values[:, 2], lw=1.0, label="drivedyn")
    if run.apex_heights:
        ax.plot(run.apex_times, run.apex_heights, "o", ms=3, label="apex of each flight")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("height [m]")
    ax.set_ylim(bottom=0.0)
    ax.set_title(f"bouncing ball, {run.law} law, e = {run.e_target:g} "
                 f"(achieved {np.mean(run.restitution) if run.restitution else np.nan:.4f})",
                 fontsize=10)
    ax.legend(fontsize=8)


def impact_duration(law: NormalLaw, mass: float, speed: float) -> float:
    """Upper estimate of the duration [s] of an impact at ``speed`` [m/s]: the undamped
    (Hertz) duration ``~3.2 delta_max / v`` stretched by the slower restitution phase of a
    dissipative law (``1 / e_achieved``, capped)."""
    n = law.exponent
    dmax = ((n + 1.0) * mass * speed**2 / (2.0 * law.stiffness)) ** (1.0 / (n + 1.0))
    e = max(law.achieved_restitution, 0.05)
    return 3.3 * dmax / speed * (0.5 + 0.5 / e)


def collide(law: str, e: float, n: float = 1.5, k: float = 1e10, mass: float = 0.85,
            speed: float = 4.472135955, gap: float = 1e-5,
            step: AdaptiveStep | None = None) -> tuple[float, Any]:
    """One impact without gravity: the ball starts ``gap`` [m] above the floor at ``speed``
    [m/s] towards it; returns the achieved restitution (final speed over ``speed``, both in
    free flight, so no interpolation is involved) and the Results.

    The default speed is the seeds' impact speed sqrt(2 g h0) = sqrt(20) m/s.
    """
    spec = bouncing_ball_spec(law=law, e=e, n=n, k=k, mass=mass, h0=gap, gravity=0.0,
                              v0=speed)
    law_ = spec.element(CONTACT).law
    t_end = gap / speed + 1.5 * impact_duration(law_, mass, speed) + 2.0 * gap / speed
    res = simulate(compile_model(spec), t_end, integrator=GeneralizedAlpha(1.0),
                   step=step or default_step(), output_times=[0.0, t_end])
    if not res.success:
        raise RuntimeError(f"collision run failed: {res.message}")
    inside = res[f"{CONTACT}.in_contact"].values[-1] > 0.5
    if inside:
        raise RuntimeError("the collision run ended in contact; t_end too short")
    v_end = float(res["ball.velocity"].values[-1, 2])
    return v_end / speed, res


RESTITUTION_TARGETS = (0.2, 0.5, 0.8, 0.95)


def restitution_table(targets: tuple[float, ...] = RESTITUTION_TARGETS,
                      laws: tuple[str, ...] = IMPACT_LAWS,
                      **kwargs: Any) -> list[dict[str, Any]]:
    """Achieved restitution of every impact law for every target, simulated (:func:`collide`)
    and predicted by the exact relation: a list of rows ``{law, e_target, chi, e_simulated,
    e_predicted, steps}``."""
    rows = []
    for law in laws:
        for e in targets:
            e_sim, res = collide(law, e, **kwargs)
            chi = NormalLaw(1.0, law=law, restitution=e).chi
            rows.append({"law": law, "e_target": e, "chi": chi, "e_simulated": e_sim,
                         "e_predicted": restitution_from_chi(chi), "steps": res.stats.steps})
    return rows
