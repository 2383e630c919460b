"""The mesh frame and the coefficients of the mesh law of one gear pair, from the gear data
and the initial configuration (plain numpy, build time): one builder per kind (parallel,
bevel, crossed), each checking that the wheels are assembled."""

from __future__ import annotations

import numpy as np

from drivedyn.elements.gears.geometry import CylindricalPair, effective_sliding_arm
from drivedyn.elements.gears.kinematics import KIND_PARALLEL, KIND_SKEW, NS
from drivedyn.elements.gears.spec import GearPair
from drivedyn.elements.gears.stiffness import iso6336_mesh_stiffness
from drivedyn.errors import ModelError


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


class MeshData:
    """Per-element constants of the kernel (see :func:`gear_kernel`)."""

    def __init__(self) -> None:
        self.kind = KIND_PARALLEL
        self.cof = np.zeros(NS)
        self.crf = np.zeros(3)
        self.inv = np.zeros(3)
        self.s0 = np.zeros(NS)
        self.W = np.zeros((2, NS))
        self.Mf = np.zeros((3, 3))
        self.n_perp = 1.0  # |n projected on A's transverse plane| (backlash conversion)
        self.k_iso: float | None = None
        self.k_single: float | None = None
        self.eps_alpha = 1.0
        self.s_eff = 0.0
        self.radius_a = 0.0  # pitch (operating) radii [m]
        self.radius_b = 0.0
        self.base_radius_a = 0.0


def _frame_coeffs(fa, fr, ft, vecs) -> np.ndarray:
    """Rows: components of each vector in the frame (fa, fr, ft)."""
    return np.array([[v @ fa, v @ fr, v @ ft] for v in vecs])


def _parallel(s: GearPair, what: str, xA, RA, xB, RB) -> MeshData:
    md = MeshData()
    a, b = RA[:, 2], RB[:, 2]
    sab = float(a @ b)
    ang = float(np.arccos(min(1.0, abs(sab))))
    if ang > s.max_misalignment:
        raise ModelError(f"{what}: the wheel axes are not parallel (angle {np.degrees(ang):.4g} "
                         f"deg > max_misalignment {np.degrees(s.max_misalignment):.4g} deg); "
                         "use kind='bevel' or 'crossed' for non-parallel axes")
    sig = 1.0 if sab > 0 else -1.0
    ext = s.internal is None
    beta = float(s.helix_angle)
    hb = s.helix_angle_b
    if hb is not None:
        want = -beta if ext else beta
        if abs(hb - want) > s.tolerance:
            hands = "opposite hands" if ext else "the same hand"
            raise ModelError(f"{what}.helix_angle_b: {'external' if ext else 'internal'} "
                             f"parallel helical gears need {hands} (helix_angle_b = "
                             f"{want!r}), got {hb!r}")
    if s.internal == "a":
        z1, z2, x1, x2 = s.teeth_b, -s.teeth_a, s.profile_shift_b, s.profile_shift_a
    elif s.internal == "b":
        z1, z2, x1, x2 = s.teeth_a, -s.teeth_b, s.profile_shift_a, s.profile_shift_b
    else:
        z1, z2, x1, x2 = s.teeth_a, s.teeth_b, s.profile_shift_a, s.profile_shift_b
    geo = CylindricalPair.build(z1, z2, s.module, s.pressure_angle, beta, x1, x2, s.addendum)
    rb1, rb2 = abs(geo.rb1), abs(geo.rb2)
    rbA, rbB = (rb2, rb1) if s.internal == "a" else (rb1, rb2)
    d = xB - xA
    da = float(d @ a)
    dperp = d - da * a
    ac0 = float(np.linalg.norm(dperp))
    aw = geo.centre_distance
    if abs(ac0 - aw) > s.tolerance * aw:
        raise ModelError(f"{what}: centre distance of the markers {ac0:.9g} m does not match "
                         f"the gear data ({'|r_B - r_A|' if not ext else 'r_A + r_B'} with "
                         f"profile shift: {aw:.9g} m) within tolerance {s.tolerance:g}")
    fr = dperp / ac0
    ft = np.cross(a, fr)
    se = -1.0 if s.internal == "b" else 1.0  # e_A = se f_r
    eA = se * fr
    tA = np.cross(a, eA)
    sm = -1.0 if s.internal == "a" else 1.0
    ca, sa = np.cos(s.pressure_angle), np.sin(s.pressure_angle)
    cbb = float(np.cos(geo.beta_b))
    md.kind = KIND_PARALLEL
    md.cof[0] = rbA * cbb
    md.cof[1] = sig * rbB * cbb * (1.0 if ext else -1.0)
    md.cof[2] = ca * np.sin(beta)
    Rinv = rbA + rbB if ext else abs(rbB - rbA)
    if not Rinv < ac0:
        raise ModelError(f"{what}: centre distance {ac0:.6g} m is below the base radii sum "
                         f"{Rinv:.6g} m")
    tq = np.sqrt(ac0**2 - Rinv**2)
    md.inv[:] = ((-1.0 if ext else 1.0) * cbb, Rinv, tq)
    cwt = Rinv / ac0
    rwA, rwB = rbA / cwt, rbB / cwt
    md.s0[:] = (-np.arctan2(d @ RA[:, 1], d @ RA[:, 0]), -np.arctan2(d @ RB[:, 1], d @ RB[:, 0]),
                da, ac0, 0.0)
    lam = np.cos(beta) * a + np.sin(beta) * tA
    tB = sig * (-1.0 if ext else 1.0) * tA
    md.W[0] = (rwA * (tA @ lam), -rwB * (tB @ lam), -(lam @ a), -(lam @ fr), 0.0)
    md.s_eff = effective_sliding_arm(geo.eps_1, geo.eps_2, geo.p_bt)
    md.W[1] = (md.s_eff, -sig * md.s_eff, 0.0, 0.0, 0.0)
    md.Mf = _frame_coeffs(a, fr, ft, (tA, eA, a))
    n = ca * (np.cos(beta) * tA - np.sin(beta) * a) + sm * sa * eA
    md.n_perp = float(np.linalg.norm(n - (n @ a) * a))
    md.eps_alpha = geo.eps_alpha
    md.radius_a, md.radius_b = rwA, rwB
    md.base_radius_a = rbA
    eps = s.contact_ratio if s.contact_ratio is not None else geo.eps_alpha
    iso = iso6336_mesh_stiffness(z1, z2, abs(beta), s.pressure_angle, eps, s.face_width, x1, x2,
                                 s.dedendum, s.rim_factor, s.youngs_modulus)
    md.k_iso, md.k_single = iso.k_mesh, iso.k_single
    return md


def _skew_common(md: MeshData, s: GearPair, RA, RB, d, rA, rB, tA, tB, eA, lam, tau, m,
                 what: str) -> None:
    """Coefficients shared by bevel and crossed pairs (frame from the two axes)."""
    a, b = RA[:, 2], RB[:, 2]
    bp = b - (b @ a) * a
    if np.linalg.norm(bp) < 0.05:
        raise ModelError(f"{what}: the wheel axes are (nearly) parallel; use kind='parallel'")
    fr = _unit(bp)
    ft = np.cross(a, fr)
    ca, sa = np.cos(s.pressure_angle), np.sin(s.pressure_angle)
    n = ca * tau + sa * m
    md.kind = KIND_SKEW
    md.cof[0] = rA * (tA @ n)
    md.cof[1] = -rB * (tB @ n)
    md.cof[2:5] = [-ca * (tau @ f) for f in (a, fr, ft)]
    md.crf[:] = [-sa * (m @ f) for f in (a, fr, ft)]
    md.s0[:] = (-np.arctan2(b @ RA[:, 1], b @ RA[:, 0]), -np.arctan2(a @ RB[:, 1], a @ RB[:, 0]),
                d @ a, d @ fr, d @ ft)
    md.W[0] = (rA * (tA @ lam), -rB * (tB @ lam), -(lam @ a), -(lam @ fr), -(lam @ ft))
    md.Mf = _frame_coeffs(a, fr, ft, (tA, eA, a))
    md.n_perp = float(np.linalg.norm(n - (n @ a) * a))
    md.radius_a, md.radius_b = rA, rB
    md.base_radius_a = md.cof[0] / md.n_perp


def _bevel(s: GearPair, what: str, xA, RA, xB, RB) -> MeshData:
    md = MeshData()
    a, b = RA[:, 2], RB[:, 2]
    beta = float(s.helix_angle)
    if s.helix_angle_b is not None and abs(s.helix_angle_b + beta) > s.tolerance:
        raise ModelError(f"{what}.helix_angle_b: bevel gears need opposite spiral hands "
                         f"(helix_angle_b = {-beta!r}), got {s.helix_angle_b!r}")
    gA, gB = float(s.cone_angle_a), float(s.cone_angle_b)
    cb = np.cos(beta)
    rA = s.teeth_a * s.module / (2.0 * cb)
    rB = s.teeth_b * s.module / (2.0 * cb)
    Rm = rA / np.sin(gA)
    if abs(rB / np.sin(gB) - Rm) > s.tolerance * Rm:
        raise ModelError(f"{what}: cone angles do not fit the tooth numbers (z_A / sin gamma_A "
                         f"= {s.teeth_a / np.sin(gA):.6g}, z_B / sin gamma_B = "
                         f"{s.teeth_b / np.sin(gB):.6g})")
    # apex: closest points of the two axis lines
    w0 = xA - xB
    ab = a @ b
    den = 1.0 - ab * ab
    if den < 1e-6:
        raise ModelError(f"{what}: the wheel axes are (nearly) parallel; use kind='parallel'")
    ta = (ab * (b @ w0) - (a @ w0)) / den
    tb = ((b @ w0) - ab * (a @ w0)) / den
    PA, PB = xA + ta * a, xB + tb * b
    if np.linalg.norm(PA - PB) > s.tolerance * Rm:
        raise ModelError(f"{what}: bevel wheel axes do not intersect (distance "
                         f"{np.linalg.norm(PA - PB):.6g} m)")
    O = 0.5 * (PA + PB)
    LA, LB = float((xA - O) @ a), float((xB - O) @ b)
    for lab, L, g in (("a", LA, gA), ("b", LB, gB)):
        if abs(abs(L) - Rm * np.cos(g)) > s.tolerance * Rm:
            raise ModelError(f"{what}: marker {lab.upper()} is {abs(L):.9g} m from the cone "
                             f"apex, the gear data need R_m cos(gamma_{lab}) = "
                             f"{Rm * np.cos(g):.9g} m (centre of the mean pitch circle)")
    ao, bo = np.sign(LA) * a, np.sign(LB) * b
    Sig = float(np.arccos(np.clip(ao @ bo, -1.0, 1.0)))
    if abs(Sig - (gA + gB)) > s.tolerance:
        raise ModelError(f"{what}: shaft angle {np.degrees(Sig):.6g} deg does not match "
                         f"cone_angle_a + cone_angle_b = {np.degrees(gA + gB):.6g} deg")
    g = _unit(np.sin(gB) * ao + np.sin(gA) * bo)
    P = O + Rm * g
    eA = _unit((P - xA) - ((P - xA) @ a) * a)
    eB = _unit((P - xB) - ((P - xB) @ b) * b)
    tA, tB = np.cross(a, eA), np.cross(b, eB)
    toA = np.cross(ao, eA)
    lam = np.cos(beta) * g + np.sin(beta) * toA
    m = _unit(eA - (eA @ g) * g)
    tau = np.sign(LA) * (np.cos(beta) * toA - np.sin(beta) * g)
    _skew_common(md, s, RA, RB, xB - xA, rA, rB, tA, tB, eA, lam, tau, m, what)
    # virtual cylindrical gears (Tredgold) for the contact ratio, friction arm and stiffness
    zvA, zvB = s.teeth_a / np.cos(gA), s.teeth_b / np.cos(gB)
    geo = CylindricalPair.build(zvA, zvB, s.module, s.pressure_angle, beta, s.profile_shift_a,
                                s.profile_shift_b, s.addendum)
    md.eps_alpha = geo.eps_alpha
    md.s_eff = effective_sliding_arm(geo.eps_1, geo.eps_2, geo.p_bt)
    md.W[1] = (md.s_eff * (a @ g), -md.s_eff * (b @ g), 0.0, 0.0, 0.0)
    eps = s.contact_ratio if s.contact_ratio is not None else geo.eps_alpha
    iso = iso6336_mesh_stiffness(zvA, zvB, abs(beta), s.pressure_angle, eps, s.face_width,
                                 s.profile_shift_a, s.profile_shift_b, s.dedendum, s.rim_factor,
                                 s.youngs_modulus)
    md.k_iso, md.k_single = iso.k_mesh, iso.k_single
    return md


def _crossed(s: GearPair, what: str, xA, RA, xB, RB) -> MeshData:
    md = MeshData()
    a, b = RA[:, 2], RB[:, 2]
    bA, bB = float(s.helix_angle), float(s.helix_angle_b)
    rA = s.teeth_a * s.module / (2.0 * abs(np.cos(bA)))
    rB = s.teeth_b * s.module / (2.0 * abs(np.cos(bB)))
    d = xB - xA
    dist = float(np.linalg.norm(d))
    if abs(dist - (rA + rB)) > s.tolerance * (rA + rB):
        raise ModelError(f"{what}: centre distance of the markers {dist:.9g} m does not match "
                         f"r_A + r_B = {rA + rB:.9g} m within tolerance {s.tolerance:g}")
    for lab, ax in (("a", a), ("b", b)):
        if abs(d @ ax) > s.tolerance * dist:
            raise ModelError(f"{what}: the markers are not on the common perpendicular of the "
                             f"axes (offset along the axis of wheel {lab.upper()}: "
                             f"{d @ ax:.6g} m)")
    eA = d / dist
    eB = -eA
    tA, tB = np.cross(a, eA), np.cross(b, eB)
    lamA = np.cos(bA) * a + np.sin(bA) * tA
    lamB = np.cos(bB) * b + np.sin(bB) * tB
    mis = float(np.linalg.norm(np.cross(lamA, lamB)))
    if mis > s.tolerance:
        Sig = np.degrees(np.arccos(min(1.0, abs(a @ b))))
        raise ModelError(f"{what}: helix angles {np.degrees(bA):.6g} and {np.degrees(bB):.6g} "
                         f"deg do not mesh at the shaft angle {Sig:.6g} deg of the markers "
                         "(the tooth traces must coincide at the pitch point)")
    tau = np.cos(bA) * tA - np.sin(bA) * a
    _skew_common(md, s, RA, RB, d, rA, rB, tA, tB, eA, lamA, tau, eA, what)
    md.W[1] = 0.0
    return md


BUILDERS = {"parallel": _parallel, "bevel": _bevel, "crossed": _crossed}
