"""TORSEN Type C model: parameter checks, the analytic quasi-static model's identities, and
the simulated bench against the analytic torque distribution ratio (TDR).

References are exact or derived here:

* frictionless set: the TDR is the tooth ratio ``rho = z_ring / z_sun`` (modes 1, 2) and
  ``1 / rho`` (modes 3, 4), whatever the geometry;
* the housing's reaction torque, rebuilt from the pocket and washer forces of the solution,
  closes the torque balance ``T_s + T_c + T_h = 0``; the external power in the housing frame
  equals the friction power of the five washers and the ``n`` pockets;
* washer loads follow the thrust paths of the docstring of
  ``drivedyn.library.differentials.torsen_c.model``;
* pocket friction alone has a closed form (derived below), which also bounds the error of the
  textbook limit :func:`~drivedyn.library.differentials.torsen_c.analytic.pocket_only_ratio`;
* the simulation without pocket friction must reproduce the analytic TDR to solver precision
  (every remaining force law is the same in both models); with pocket friction the difference
  is a documented compliance effect, bounded below.

The simulations use a short bench protocol (ramp 0.1 s, reversal 0.5-0.8 s, end 1.1 s); its
steady windows give the same TDR as the seed protocol's (checked: <= 1e-12 relative on the
shipped set), and every window is checked to be steady (ripple). The full protocol is in
``benchmarks/torsen_c_bench.py``. Parameters come from the shipped ``torsen-c`` file; values
derived from it are recomputed here, so a recalibration of the file does not break the tests.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from drivedyn.analysis.tdr import run_bench
from drivedyn.config import ModelFileError, read_library_file
from drivedyn.library.differentials import get as get_differential
from drivedyn.library.differentials.scenarios import bench_spec as _bench_spec
from drivedyn.library.differentials.torsen_c.analytic import (
    all_modes,
    bench_speeds,
    bench_tdr,
    pocket_only_ratio,
    solve,
)
from drivedyn.library.differentials.torsen_c.model import MODES, WASHERS, check_parameters, geometry
from drivedyn.model.compile import compile_model
from drivedyn.model.spec import ModelError
from drivedyn.results.recorder import model_summary
from torsen_protocol import TYPE_C_SHORT


def bench_spec(p, side, *args, **kw):
    return _bench_spec(get_differential("torsen_c"), p, side, *args, **kw)

RPM = 2 * math.pi / 60

#: short bench protocol with a constant mesh stiffness (see :mod:`torsen_protocol`)
SHORT = TYPE_C_SHORT
NO_WASHER_FRICTION = {f"washers.{w}.mu": 0.0 for w in WASHERS}


def params(extra: dict | None = None):
    """The shipped parameters with the short protocol and ``extra`` overrides."""
    return read_library_file("torsen-c", {**SHORT, **(extra or {})})[0]


SHIPPED = params()
NO_TEETH = params({"gears.tooth_friction": 0.0})


def _set(name: str) -> dict:
    """Overrides of the parameter sets that are simulated."""
    p = SHIPPED
    return {
        "shipped": {},
        "shipped, no tooth friction": {"gears.tooth_friction": 0.0},
        # 3 planets: 50 + 70 = 120 is divisible by 3
        "3 planets": {"gears.planets": 3},
        "pocket mu 0.25, washer mu x0.6": {
            "pockets.mu": 0.25,
            **{f"washers.{w}.mu": 0.6 * getattr(p.washers, w).mu for w in WASHERS}},
        # 25 deg helix; the sun's tip radius shrinks to 42.9 mm, so its washer too. 10-tooth
        # planets at 25 deg undercut at 20 deg pressure angle (GearPair refuses them), so
        # this set uses 22.5 deg (practical limit 8.7 teeth)
        "helix 25 deg": {"gears.helix_angle": "25 deg", "spline.helix_angle": "35 deg",
                         "washers.sun_housing.r_ext": "42 mm",
                         "gears.pressure_angle": "22.5 deg"},
        # mirrored hands: drive and coast exchange their washers
        "left hand": {"gears.helix_angle": -p.gears.helix_angle,
                      "spline.helix_angle": -p.spline.helix_angle},
        # the identities below (exact agreement, speed independence) hold without the
        # spline friction: a stuck spline sits near its Coulomb limit by an amount that
        # depends on the loading history (the analytic model takes the limit itself);
        # test_spline_friction_* check it
        "no pocket friction": {"pockets.mu": 0.0, "spline.mu": 0.0},
        # Newton to the default 1e-8 of each equation's force sum (the file's 1e-5 is set for
        # speed): identities checked to the solver's precision
        "shipped, Newton 1e-8": {"solver.newton.tol": 1e-8, "spline.mu": 0.0},
    }[name]


@functools.cache
def bench(name: str, side: str, torque: float | None = None,
          speed_diff: float | None = None):
    """Simulated bench side of a parameter set (cached for the module)."""
    run = run_bench(params(_set(name)), side, torque=torque, speed_diff=speed_diff)
    assert run.success, run.message
    return run


# -- parameter checks --------------------------------------------------------------------


def test_shipped_parameters_and_geometry():
    """The shipped set is accepted, and the derived geometry is that of a coaxial helical
    planetary set (so the refusals below are specific to the broken key)."""
    p = SHIPPED
    g = p.gears
    geo = check_parameters(p)
    mt = g.module / math.cos(g.helix_angle)  # transverse module
    assert geo.r_sun == pytest.approx(g.teeth_sun * mt / 2, rel=1e-14)
    assert geo.r_ring == pytest.approx(g.teeth_ring * mt / 2, rel=1e-14)
    # coaxial: the planet centres are r_s + r_p = r_r - r_p from the axis
    assert geo.carrier_radius == pytest.approx(geo.r_ring - geo.r_planet, rel=1e-14)
    assert geo.rho == g.teeth_ring / g.teeth_sun
    assert geo.lead == pytest.approx(2 * math.pi * p.spline.radius
                                     / math.tan(p.spline.helix_angle), rel=1e-14)
    for name in WASHERS:  # r_m of a uniformly loaded annulus, M = mu F r_m
        w = getattr(p.washers, name)
        ri, re = w.r_int, w.r_ext
        integral = (2 * math.pi * (re**3 - ri**3) / 3) / (math.pi * (re**2 - ri**2))
        assert geo.washer_radius[name] == pytest.approx(integral, rel=1e-14)


@pytest.mark.parametrize(("overrides", "key"), [
    pytest.param({"gears.teeth_ring": 72}, "gears.teeth_ring", id="ring!=sun+2planet"),
    # 50 + 70 = 120 is not divisible by 7
    pytest.param({"gears.planets": 7}, "gears.planets", id="planets-not-dividing"),
    pytest.param("opposite spline hand", "spline.helix_angle", id="spline-hand"),
    pytest.param("ring_case r_int = r_ext", "washers.ring_case.r_int", id="washer-rint=rext"),
    pytest.param({"washers.sun_coupling.r_int": "30 mm"}, "washers.sun_coupling.r_int",
                 id="washer-rint>rext"),
])
def test_inconsistent_parameters_are_refused(overrides, key):
    """Each impossible set is refused with a ModelError naming the key, by the parameter
    check, by the model builder and by the analytic model."""
    p = SHIPPED
    if overrides == "opposite spline hand":
        overrides = {"spline.helix_angle": -p.spline.helix_angle}
    elif overrides == "ring_case r_int = r_ext":
        overrides = {"washers.ring_case.r_int": p.washers.ring_case.r_ext}
    bad = params(overrides)  # schema-valid: only the model check can refuse it
    for call in (lambda: check_parameters(bad), lambda: bench_spec(bad, "rear"),
                 lambda: all_modes(bad)):
        with pytest.raises(ModelError, match=key.replace(".", r"\.")):
            call()


@pytest.mark.parametrize(("overrides", "key", "what"), [
    ({"bodies.sun.mass": "-0.8 kg"}, "bodies.sun.mass", "must be > 0"),
    ({"gears.teeth_moon": 3}, "gears.teeth_moon", "unknown key"),
    ({"pockets.muu": 0.1}, "pockets.muu", "unknown key"),
])
def test_schema_errors_name_the_key(overrides, key, what):
    with pytest.raises(ModelFileError) as exc:
        params(overrides)
    assert key in str(exc.value) and what in str(exc.value)


def test_bench_arguments_are_checked():
    for kw, word in (({"side": "middle"}, "side"), ({"side": "rear", "torque": -5.0}, "torque"),
                     ({"side": "rear", "speed_diff": 0.0}, "speed")):
        with pytest.raises(ModelError, match=word):
            bench_spec(SHIPPED, **kw)


def test_bench_model_structure():
    """Per planet a parallel-axes guide, a pocket and two end faces on the floors, two
    meshes; five washers; without ``pockets.end_faces`` a planar guide instead (both joint
    families' tangents are checked by the registry loop of tests/elements/test_tangents.py,
    which runs over every registered family)."""
    p = params({"gears.planets": 3})
    model = compile_model(bench_spec(p, "front")[0])
    count = {k: v["count"] for k, v in model_summary(model)["elements"].items()}
    assert count["parallel_axes"] == 3 and "planar" not in count
    assert count["journal_contact"] == 3
    assert count["gear_pair"] == 6
    assert count["thrust_washer_contact"] == 5 + 2 * 3
    assert count["screw"] == 1
    p = params({"gears.planets": 3, "pockets.end_faces": False})
    count = {k: v["count"] for k, v in model_summary(compile_model(
        bench_spec(p, "front")[0]))["elements"].items()}
    assert count["planar"] == 3 and count["thrust_washer_contact"] == 5


# -- analytic model ----------------------------------------------------------------------

ANALYTIC_SETS = ["shipped", "3 planets", "helix 25 deg", "left hand"]


@pytest.mark.parametrize("name", ANALYTIC_SETS)
def test_analytic_frictionless_is_the_tooth_ratio(name):
    """Without friction the planets are ideal levers: T_ring / T_sun = r_r / r_s exactly."""
    p = params(_set(name))
    rho = p.gears.teeth_ring / p.gears.teeth_sun
    want = [rho, rho, 1 / rho, 1 / rho]
    # rel 1e-12: the Newton solve stops at xtol 1e-13 on O(1) scaled unknowns
    assert all_modes(p, friction_scale=0.0) == pytest.approx(want, rel=1e-12)
    zero = params({**_set(name), **NO_WASHER_FRICTION, "pockets.mu": 0.0,
                   "gears.tooth_friction": 0.0})
    assert all_modes(zero) == pytest.approx(want, rel=1e-12)
    # vehicle (housing torque given, outputs at different speeds, centrifugal load): the
    # rear/front split is rho too
    q = solve(p, _vehicle_speeds(p, 2.0), "housing", 125.0, friction_scale=0.0)
    assert q.torque_coupling / q.torque_sun == pytest.approx(rho, rel=1e-12)


def _vehicle_speeds(p, diff: float, mean: float = 30.0):
    """(housing, sun, coupling) speeds with rear - front = diff (Willis)."""
    g = p.gears
    ws, wc = mean - diff / 2, mean + diff / 2
    return ((g.teeth_sun * ws + g.teeth_ring * wc) / (g.teeth_sun + g.teeth_ring), ws, wc)


def _cases(p):
    """(speeds, known, torque) of the four bench modes and four vehicle states."""
    out = []
    for mode in (1, 2, 3, 4):
        _, _, side, drive = MODES[mode - 1]
        speeds, sgn = bench_speeds(p, side, drive, p.bench.speed_diff)
        out.append((speeds, "coupling" if side == "rear" else "sun", sgn * p.bench.torque))
    for torque in (125.0, -125.0):
        for diff in (2.0, -2.0):
            out.append((_vehicle_speeds(p, diff), "housing", torque))
    return out


def _housing_reaction(p, q, speeds) -> float:
    """External torque on the housing rebuilt from the internal forces of the solution: the
    housing (with the case) holds against the pocket forces of the n planets, the friction
    couples of their end faces on the pocket floors and the friction of washers W1, W3, W4,
    W5 (W2 is between sun and coupling)."""
    geo = geometry(p)
    n = p.gears.planets
    wh, ws, wc = speeds
    wpr = -(ws - wh) * p.gears.teeth_sun / p.gears.teeth_planet
    sig = np.sign(wpr)
    e = np.array([math.cos(q.pocket_angle), math.sin(q.pocket_angle), 0.0])
    z = np.array([0.0, 0.0, 1.0])
    mu_p = p.pockets.mu
    # force of the planet on its pocket (opposite of the pocket's force -N e - s mu N z x e)
    # at the contact point, planet centre + r_tip e
    f = q.pocket_force * e + sig * mu_p * q.pocket_force * np.cross(z, e)
    point = np.array([geo.carrier_radius, 0.0, 0.0]) + geo.r_tip_planet * e
    m_pockets = n * np.cross(point, f)[2]
    # the floor's friction couple on a planet is -sig mu_p |A_p| r_e: the housing gets +
    m_pockets += n * sig * mu_p * abs(q.planet_thrust) * geo.r_end
    M = q.washer_torque
    # washer friction opposes the spin of the gear face relative to the housing face, so the
    # housing receives + M sgn(relative spin)
    m_washers = (M["sun_housing"] * np.sign(ws - wh)
                 + (M["coupling_case"] + M["ring_housing"] + M["ring_case"]) * np.sign(wc - wh))
    return -(m_pockets + m_washers)


@pytest.mark.parametrize("name", ANALYTIC_SETS)
def test_analytic_torque_balance_from_internal_forces(name):
    p = params(_set(name))
    for speeds, known, torque in _cases(p):
        q = solve(p, speeds, known, torque)
        th = _housing_reaction(p, q, speeds)
        scale = abs(torque)
        # 1e-9: equation residuals are ~1e-13 of the torque (q.residual); the rebuilt torque
        # sums forces of size ~T / r, each exact to the same relative precision
        assert q.residual < 1e-10
        assert q.torque_sun + q.torque_coupling + th == pytest.approx(0.0, abs=1e-9 * scale)
        if known == "housing":
            assert th == pytest.approx(torque, rel=1e-9)


@pytest.mark.parametrize("name", ANALYTIC_SETS)
def test_analytic_power_balance(name):
    """Housing frame: external power (in - out) = the friction power of the washers, the
    pocket tips, the planets' end faces and the teeth, and the TDR is rho / efficiency (rear
    loaded) or 1 / (rho efficiency) (front loaded). An independent check of the moment
    equations: leaving out a mechanism's power (e.g. the end faces' ``mu_p |A_p| r_e
    |w_p'|``: 2.6-3.3 % of the shipped set's loss) fails at 1e-9."""
    p = params(_set(name))
    geo = geometry(p)
    n = p.gears.planets
    rho = geo.rho
    for i, (speeds, known, torque) in enumerate(_cases(p)):
        q = solve(p, speeds, known, torque)
        wh, ws, wc = speeds
        wsr, wcr = ws - wh, wc - wh
        wpr = -wsr * p.gears.teeth_sun / p.gears.teeth_planet
        spin = {"sun_housing": wsr, "sun_coupling": wc - ws, "coupling_case": wcr,
                "ring_housing": wcr, "ring_case": wcr}
        p_washers = sum(q.washer_torque[k] * abs(spin[k]) for k in WASHERS)
        p_pockets = n * p.pockets.mu * q.pocket_force * geo.r_tip_planet * abs(wpr)
        p_ends = n * p.pockets.mu * abs(q.planet_thrust) * geo.r_end * abs(wpr)
        c_s, c_r = q.tooth_couple
        p_teeth = n * (c_s * abs(wsr - wpr) + c_r * abs(wpr - wcr))
        p_friction = p_washers + p_pockets + p_ends + p_teeth
        # power of the external torques into the differential (the housing's does no work
        # in its own frame): all of it is dissipated at constant speeds
        p_ext = q.torque_sun * wsr + q.torque_coupling * wcr
        assert p_friction > 0
        # 1e-9: the power terms are products of torques exact to ~1e-13 relative
        assert p_ext == pytest.approx(p_friction, rel=1e-9)
        if i < 4:  # bench: efficiency = output power / input power
            if known == "coupling":
                p_in = q.torque_coupling * wcr
                eta = -q.torque_sun * wsr / p_in
                assert abs(q.torque_coupling / q.torque_sun) == pytest.approx(rho / eta,
                                                                              rel=1e-12)
            else:
                p_in = q.torque_sun * wsr
                eta = -q.torque_coupling * wcr / p_in
                assert abs(q.torque_sun / q.torque_coupling) == pytest.approx(
                    1 / (rho * eta), rel=1e-12)
            assert 1 - eta == pytest.approx(p_friction / p_in, rel=1e-9)


def _thrust_path(p, q, pushed_front: bool) -> dict[str, float]:
    """Washer loads of the documented thrust paths (library docstring)."""
    g = p.gears
    tb = abs(math.tan(g.helix_angle))
    A_s = tb * g.planets * abs(q.mesh_sun)
    A_r = tb * g.planets * abs(q.mesh_ring)
    # the spline's thrust: a screw with friction at its limit, the flanks' resultant leaning
    # back by the friction angle against the separation the thrust drives
    r_sp = p.spline.radius
    beta = math.atan(2 * math.pi * r_sp / abs(geometry(p).lead))
    A_c = abs(q.spline_torque) * math.tan(beta - math.atan(p.spline.mu)) / r_sp
    if pushed_front:
        return {"sun_housing": A_s + A_c, "sun_coupling": A_c, "coupling_case": 0.0,
                "ring_housing": 0.0, "ring_case": A_r + A_c}
    return {"sun_housing": 0.0, "sun_coupling": A_s, "coupling_case": A_s + A_c,
            "ring_housing": A_r + A_c, "ring_case": 0.0}


@pytest.mark.parametrize("name", ["shipped", "left hand", "helix 25 deg"])
def test_analytic_washer_loads_follow_the_thrust_paths(name):
    """Right-hand sun: drive (modes 1, 3) pushes sun and coupling to the front (W1, W2, W5
    loaded; W3, W4 free), coast (2, 4) to the rear (W2, W3, W4; W1, W5 free). A left-hand set
    exchanges the two."""
    p = params(_set(name))
    right = p.gears.helix_angle > 0
    for mode in (1, 2, 3, 4):
        _, _, side, drive = MODES[mode - 1]
        speeds, sgn = bench_speeds(p, side, drive, p.bench.speed_diff)
        q = solve(p, speeds, "coupling" if side == "rear" else "sun", sgn * p.bench.torque)
        want = _thrust_path(p, q, pushed_front=(drive == right))
        for w in WASHERS:
            assert q.washer_force[w] == pytest.approx(want[w], rel=1e-12, abs=1e-9), (mode, w)


def _pocket_only_exact(p, mode: int) -> float:
    """Bench TDR with pocket friction only (no washer friction, housing held: no centrifugal
    force). Per planet, with mesh forces F_s = F (1 - x), F_r = F (1 + x) along t, their
    radial parts (|F_s| - |F_r|) tan(alpha_t) = -2 F x tan(alpha_t), and the pocket reaction
    of magnitude N sqrt(1 + mu^2) balancing the resultant 2 F sqrt(1 + x^2 tan^2 alpha_t):
    the planet's moment r_p (F_r - F_s) = mu N r_a gives
    x = b / sqrt(1 + mu^2 - b^2 tan^2 alpha_t),  b = mu r_a / r_p,
    and rear/front = rho (1 + x)/(1 - x) when the ring drives (modes 1, 2), rho (1 - x)/(1 + x)
    when the sun drives (3, 4). pocket_only_ratio is this with x = b."""
    geo = geometry(p)
    mu = p.pockets.mu
    ta = math.tan(p.gears.pressure_angle) / math.cos(p.gears.helix_angle)
    b = mu * geo.r_tip_planet / geo.r_planet
    x = b / math.sqrt(1 + mu**2 - (b * ta) ** 2)
    k = (1 + x) / (1 - x)
    return geo.rho * k if mode in (1, 2) else k / geo.rho


@pytest.mark.parametrize("mu_p", [0.05, 0.15, 0.3])
@pytest.mark.parametrize("name", ["shipped", "helix 25 deg", "3 planets"])
def test_analytic_pocket_only_limit(name, mu_p):
    """The tips' friction alone (no washer, tooth or end-face friction): the closed form."""
    p = params({**_set(name), **NO_WASHER_FRICTION, "pockets.mu": mu_p,
                "gears.tooth_friction": 0.0, "pockets.end_faces": False})
    geo = geometry(p)
    b = mu_p * geo.r_tip_planet / geo.r_planet
    ta = math.tan(p.gears.pressure_angle) / math.cos(p.gears.helix_angle)
    x = b / math.sqrt(1 + mu_p**2 - (b * ta) ** 2)
    for mode in (1, 2, 3, 4):
        tdr = bench_tdr(p, mode)
        assert tdr == pytest.approx(_pocket_only_exact(p, mode), rel=1e-11)
        rear_front = tdr if mode in (1, 2) else 1 / tdr
        approx = pocket_only_ratio(geo.rho, mu_p, geo.r_tip_planet, geo.r_planet,
                                   ring_drives=mode in (1, 2))
        # ln((1+s)/(1-s)) has the slope 2/(1-s^2), increasing in s: by the mean value
        # theorem |ln(approx/exact)| <= 2 |x - b| / (1 - max(x, b)^2)
        bound = 2 * abs(x - b) / (1 - max(x, b) ** 2)
        assert abs(math.log(approx / rear_front)) <= bound * (1 + 1e-9) + 1e-14


def test_analytic_tdr_independent_of_torque_and_speed():
    """The quasi-static equations are homogeneous of degree 1 in the forces (Coulomb
    friction, no centrifugal force on the bench) and see the speeds only through their
    signs: the TDR cannot depend on the torque level or the speed difference."""
    p = SHIPPED
    nominal = all_modes(p)
    for kw in ({"torque": 60.0}, {"torque": 250.0}, {"speed_diff": 10 * RPM},
               {"speed_diff": 40 * RPM}):
        assert all_modes(p, **kw) == pytest.approx(nominal, rel=1e-12)


# -- simulated bench ---------------------------------------------------------------------

# Steadiness: peak-to-peak of the instantaneous torque ratio over a window, relative to the
# TDR. The comparisons to solver precision need windows steady to round-off: RIPPLE_EXACT
# (measured <= 2e-10 without pocket friction). With pocket friction the torque reversal
# (0.65 s, zero load) lets each planet cross its pocket clearance and strike the other wall;
# a planet left a few um off its seat by the strike creeps back at the rate friction allows
# (its spin slides on the wall, so the wall's friction resists any creep across that
# sliding), measured time constant 0.07 s at pocket mu 0.25 and 20 rpm. Where a planet lands
# after a strike depends on the steps taken through it, as any impact's outcome within the
# step tolerance does: 3.4 um off its seat under one step-size rule, on it under another,
# coast ripple 7.9e-5 against 3.4e-9 and window-mean TDRs 3e-5 apart. So the bound for a
# comparison with the analytic model is what that comparison can afford: a twentieth of its
# tolerance (the window mean moves by less than the ripple). Fails when the window starts
# inside the transition: the coast window from 0.7 s, ripple 4.5e-3.
RIPPLE_EXACT = 1e-6


def _check_steady(run, bound: float) -> None:
    for mode, r in run.ripple.items():
        assert r < bound, f"mode {mode}: not steady, ripple {r:.2e} (bound {bound:.1e})"


@pytest.mark.slow
@pytest.mark.parametrize("side", ["rear", "front"])
def test_sim_exact_without_pocket_friction(side):
    """Without pocket friction the planet's moment balance gives equal mesh forces on its
    base circles whatever the planet's position, so the radial forces and the planet's small
    displacement in its pocket drop out, and the thrusts (F_n cos(alpha_n) sin(beta) against
    the torque F_n cos(beta_b) r_b: a constant ratio), spline thrust and washer friction
    (mu N r_m above eps_v) are the analytic model's own laws. Measured: <= 3.5e-13; 1e-8
    allows for the solver's residual tolerances."""
    run = bench("no pocket friction", side)
    _check_steady(run, RIPPLE_EXACT)
    p = params(_set("no pocket friction"))
    for mode, tdr in run.tdr.items():
        assert tdr == pytest.approx(bench_tdr(p, mode), rel=1e-8)


# Simulated vs analytic with pocket friction. The analytic model keeps each planet at its
# nominal centre and the meshes at the nominal pressure angle. In the simulation the planet
# rests in its pocket displaced by clearance + Hertz penetration (~50 um) along the pocket
# normal, which is tilted from the tangent by about the friction angle; the radial part
# (3-5 um) changes the operating pressure angle (radial mesh forces +-0.05 %), and where it
# moves the planet outwards (modes 1, 2) it also closes the zero-backlash internal mesh on
# its coast flank (ring mesh radial force +5 % at 125 N m). Radial forces change the TDR
# only through the pocket normal force, i.e. multiplied by mu_p (without pocket friction the
# models agree to 1e-12, test above). Measured at mu_p = 0.15: <= 0.10 % (modes 1, 2),
# <= 0.004 % (modes 3, 4) on three geometries and 60-250 N m; at mu_p = 0.25: 0.7 %.
# Asserted: the issue's 2 % for every set, and 0.5 % (5x the largest measured) for the sets
# with the shipped pocket coefficient.
TOL_ISSUE = 0.02
TOL_SHIPPED_POCKET = 0.005

SIM_CASES = [
    ("shipped", "rear"), ("shipped", "front"),
    ("3 planets", "rear"), ("3 planets", "front"),
    ("pocket mu 0.25, washer mu x0.6", "rear"),
    ("helix 25 deg", "front"),
    ("left hand", "rear"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("name", "side"), SIM_CASES)
def test_sim_tdr_matches_analytic(name, side):
    run = bench(name, side)
    p = params(_set(name))
    tol = TOL_SHIPPED_POCKET if p.pockets.mu == SHIPPED.pockets.mu else TOL_ISSUE
    _check_steady(run, tol / 20)
    for mode, tdr in run.tdr.items():
        ana = bench_tdr(p, mode)
        assert abs(tdr / ana - 1) < tol, f"mode {mode}: sim {tdr:.5f}, analytic {ana:.5f}"


@pytest.mark.slow
@pytest.mark.parametrize(("name", "side"), [("shipped", "rear"), ("shipped", "front"),
                                            ("left hand", "rear")])
def test_sim_washer_loads_follow_the_thrust_paths(name, side):
    """Window-mean washer forces of the simulation: the documented washers carry the load
    (the others are separated: exactly 0 N) and the values follow the analytic ones. The
    loads are mesh and spline thrusts, so they carry the TDR's model difference (pocket
    force ~0.2 % at most, see above): 1 %."""
    run = bench(name, side)
    p = params(_set(name))
    res = run.results
    t = res["time"].values
    right = p.gears.helix_angle > 0
    modes = (1, 2) if side == "rear" else (3, 4)
    for mode, window in zip(modes, (p.bench.window_drive, p.bench.window_coast), strict=True):
        _, _, _, drive = MODES[mode - 1]
        k = (t >= window[0]) & (t <= window[1])
        speeds, sgn = bench_speeds(p, side, drive, p.bench.speed_diff)
        q = solve(p, speeds, "coupling" if side == "rear" else "sun", sgn * p.bench.torque)
        want = _thrust_path(p, q, pushed_front=(drive == right))
        top = max(want.values())
        for w in WASHERS:
            got = res[f"{w}.normal_force"].values[k]
            if want[w] == 0.0:
                assert np.all(got == 0.0), (mode, w, got.max())
            else:
                assert got.mean() == pytest.approx(want[w], rel=0.01), (mode, w)
                assert got.mean() > 0.1 * top


@pytest.mark.slow
def test_sim_power_balance():
    """Steady state: the power supplied by the applied torque and the speed control equals
    the power dissipated by the contacts (kinetic and mesh energies are constant).

    Checked with Newton at 1e-8: the identity holds to what Newton leaves in the equations.
    With Newton at 1e-6 the largest gap is 7e-8 of the dissipated power (measured), which
    that tolerance allows (each residual within 1e-6 of its equation's force sum); at 1e-8 it
    is 1.9e-9, at the coast window's start (the last of the transition's transient; 2e-11
    in the drive window)."""
    run = bench("shipped, Newton 1e-8", "rear")
    res = run.results
    t = res["time"].values
    diss_vars = [v for v in res.dataset.data_vars if v.endswith(".dissipated_power")]
    for window in (SHIPPED.bench.window_drive, SHIPPED.bench.window_coast):
        k = (t >= window[0]) & (t <= window[1])
        supplied = (res["applied_torque.power"].values[k]
                    + res["speed_control.power"].values[k])
        dissipated = sum(res[v].values[k] for v in diss_vars)
        # measured 1.9e-9 relative (see above)
        assert np.max(np.abs(supplied - dissipated)) < 1e-8 * dissipated.mean()


@pytest.mark.slow
def test_sim_tdr_independent_of_torque():
    """The analytic TDR is exactly torque-independent (test above). The simulated one varies
    with the load only through the compliance effect bounded above (the clearance is fixed,
    the deflections grow with the load): measured spread <= 0.11 % from the nominal over
    60-250 N m without tooth friction; asserted 0.5 % (the sim-vs-analytic bound). Tooth
    friction on the flank the compliance closes adds to it (the analytic model has one flank
    per mesh): with the file's 0.10, 0.77 % from the analytic TDR at 60 N m, which the
    validation case checks at its 2 %."""
    nominal = bench("shipped, no tooth friction", "rear")
    for torque in (60.0, 250.0):
        run = bench("shipped, no tooth friction", "rear", torque=torque)
        _check_steady(run, TOL_SHIPPED_POCKET / 20)
        for mode, tdr in run.tdr.items():
            assert abs(tdr / nominal.tdr[mode] - 1) < TOL_SHIPPED_POCKET, (torque, mode)
            assert abs(tdr / bench_tdr(NO_TEETH, mode) - 1) < TOL_SHIPPED_POCKET


@pytest.mark.slow
def test_sim_tdr_independent_of_speed():
    """At constant speeds nothing in the model depends on the speed magnitude once every
    sliding speed exceeds eps_v: the regularised friction is exactly Coulomb there, damping
    forces vanish (all rates are zero), and with the housing held there is no centrifugal or
    gyroscopic load (planet axes fixed). So the TDR at 10 and 40 rpm equals the nominal 20
    rpm one to solver precision: with Newton at 1e-8, measured <= 3.5e-11; asserted 1e-9.
    (With Newton at 1e-6, 4.4e-9: what that tolerance leaves.)"""
    p = SHIPPED
    eps_v = p.contact.eps_v
    nominal = bench("shipped, Newton 1e-8", "rear")
    for rpm in (10.0, 40.0):
        run = bench("shipped, Newton 1e-8", "rear", speed_diff=rpm * RPM)
        _check_steady(run, RIPPLE_EXACT)
        for mode, tdr in run.tdr.items():
            assert tdr == pytest.approx(nominal.tdr[mode], rel=1e-9), (rpm, mode)
        if rpm == 10.0:  # every slip (loaded or not) is above eps_v: Coulomb branch
            res = run.results
            t = res["time"].values
            for window in (p.bench.window_drive, p.bench.window_coast):
                k = (t >= window[0]) & (t <= window[1])
                names = [*WASHERS, *(f"planet{i + 1}_pocket" for i in range(p.gears.planets))]
                for name in names:
                    slip = np.abs(res[f"{name}.sliding_speed"].values[k])
                    assert slip.min() > 5 * eps_v, (name, slip.min())


@pytest.mark.slow
def test_stiffness_variation_keeps_the_tdr():
    """The shipped file varies the mesh stiffness with the tooth pairs in contact: the meshes
    then ripple at the mesh frequency, but the window-mean TDR stays that of the constant
    stiffness (measured 0.08 % and 0.12 %) and of the analytic model."""
    p = read_library_file("torsen-c", {k: v for k, v in SHORT.items()
                                       if k != "gears.stiffness_variation"})[0]
    assert p.gears.stiffness_variation
    run = run_bench(p, "rear")
    assert run.success, run.message
    constant = bench("shipped", "rear")
    for mode, tdr in run.tdr.items():
        assert abs(tdr / constant.tdr[mode] - 1) < 3e-3, (mode, tdr, constant.tdr[mode])
        assert abs(tdr / bench_tdr(p, mode) - 1) < TOL_SHIPPED_POCKET


def test_planet_end_faces_dry_or_with_film():
    """Each planet has two end faces on the housing's pocket floors (``end_gap`` beyond its
    ends): thrust-washer contacts, or squeeze films with ``pockets.end_film``; the Type B's
    element gears get theirs from the same builder."""
    from drivedyn.config import read_library_file
    from drivedyn.elements.contact import ThrustWasherContact
    from drivedyn.elements.contact.squeeze_film import SqueezeFilm
    from drivedyn.library.differentials.torsen_b.model import build_spec as build_b
    from drivedyn.library.differentials.torsen_c.model import build_spec as build_c

    for sets, kind in (([], ThrustWasherContact), (["pockets.end_film=true"], SqueezeFilm)):
        p, _, _ = read_library_file("torsen-c", sets)
        sp, _ = build_c(p)
        ends = [e for e in sp.elements if "_end_" in e.name]
        assert len(ends) == 2 * p.gears.planets and all(isinstance(e, kind) for e in ends)
        f, r = sp.markers["floor_planet1f"], sp.markers["floor_planet1r"]
        half = p.gears.face_width / 2
        assert r.position[2] - f.position[2] == pytest.approx(2 * (half + p.pockets.end_gap))
        assert f.body == r.body == "housing"
    pb, _, _ = read_library_file("torsen-b")
    sb, _ = build_b(pb)
    ends = [e.name for e in sb.elements if "_end_" in e.name]
    assert len(ends) == 4 * pb.gears.pairs and "a1_end_l" in ends and "b1_end_r" in ends


def test_spline_friction_sticks_at_its_limit_and_relieves_the_washers():
    """The shipped spline friction (``spline.mu``, stick stiffness 1e9 N/m) reaches the
    spline's screw joint, whose flanks stick through the TDR windows (no friction power) at
    their Coulomb limit ``mu N`` (the limit state of a spline stiffer
    than the washers, docs/torsen_c.md), and the stuck spline takes axial load off the
    washers: the mode 1 TDR drops against the file without it (by 7 % on the full
    protocol). Fails if the friction is not passed to the joint (TDR unchanged), is
    regularised (the flanks slide: friction power) or if the stick stiffness is too soft
    to reach the limit (1e8 N/m: 44 % of it, seen)."""
    p = SHIPPED
    spec, _ = bench_spec(p, "rear")
    spline = next(e for e in spec.elements if e.name == "spline")
    assert (spline.friction, spline.radius) == (p.spline.mu, p.spline.radius) != (0.0, 0.0)
    run = run_bench(p, "rear")
    base = run_bench(params({"spline.mu": 0.0}), "rear")
    res = run.results
    t = res.values("time")
    k = (t >= p.bench.window_drive[0]) & (t <= p.bench.window_drive[1])
    f = res.values("spline.friction_force")[k]
    axial = res.values("spline.force_z")[k]
    # at the limit the flanks' resultant leans back by the friction angle against the
    # thrust: axial force N (sin(beta) - mu cos(beta)), friction mu N
    b, mu = p.spline.helix_angle, p.spline.mu
    limit = mu * np.abs(axial) / (math.sin(b) - mu * math.cos(b))
    ratio = np.abs(f) / limit
    assert ratio.min() > 0.97 and ratio.max() < 1.0 + 1e-9
    assert np.abs(res.values("spline.friction_power")[k]).max() == 0.0
    assert run.tdr[1] < 0.97 * base.tdr[1]
