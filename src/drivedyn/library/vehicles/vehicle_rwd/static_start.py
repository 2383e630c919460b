"""The initial state of a RWD vehicle run: the built model moved to the parked vehicle's
static equilibrium, so that a run does not begin with the frame springing back from its
unloaded shape (:func:`static_start`; ``drivedyn vehicle`` and ``drivedyn run`` start
from it)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from drivedyn.library.vehicles.vehicle_rwd.configurations import CONFIGS
from drivedyn.library.vehicles.vehicle_rwd.model import Layout, build_spec
from drivedyn.library.vehicles.vehicle_rwd.schema import WHEELS, VehicleRWDFile
from drivedyn.library.vehicles.vehicle_rwd.wind_up import wind_up
from drivedyn.model.compile import compile_model
from drivedyn.rotations import exp_so3
from drivedyn.solver.statics import solve_static


def _minimal_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation turning unit vector ``a`` onto unit vector ``b`` about their normal."""
    c = float(a @ b)
    k = np.cross(a, b)
    s = float(np.linalg.norm(k))
    if s < 1e-15:
        return np.eye(3)
    k /= s
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * K + (1.0 - c) * K @ K


def static_start(p: VehicleRWDFile, torsen: dict, base_dir: str | Path, model: Any,
                 lay: Layout) -> Any:
    """The initial state of ``model`` moved to the static equilibrium of the parked vehicle
    (:func:`static`'s solution), so that a run does not begin with the frame springing back
    from its unloaded shape (it sags by 10 mm under the body).

    Every body and node the two models share takes its static position and orientation,
    except the differential's and the pinion's (``rear_*``, ``pinion_shaft``: they move
    rigidly with the rear carrier, since a TORSEN is solved as the open differential), the
    propeller shaft's slip yoke (turned about its axis to square its joint with the pinion)
    and the half-shafts and plungers (turned
    about their inner joint so that the shaft reaches its wheel's static centre; the plunger
    slides). Velocities stay the model's own (the vehicle's speed, the wheels' spins).
    With ``run.wind_up`` the driveline is then wound up by the engine's first torque
    (:func:`~.wind_up.wind_up`: its plays closed, its shafts twisted)."""

    q = p.model_copy(update={"engine": p.engine.model_copy(update={"throttle": 0.0,
                                                                   "idle_throttle": 0.0})})
    if q.differentials.rear == "torsen-b":  # floating gears: no stiffness at rest
        d = q.differentials.model_copy(update={"rear": CONFIGS["open"]})
        q = q.model_copy(update={"differentials": d})
    spec_s, _ = build_spec(q, torsen, base_dir, parked=True)
    ms = compile_model(spec_s)
    ss = solve_static(ms, max_iter=100)
    s0 = ms.initial_state()
    st = model.initial_state()
    x0 = st.x.copy()
    R0 = st.R.copy()
    jc = ms.node_index["carrier"]
    Qc = ss.R[jc] @ s0.R[jc].T

    def carried(point: np.ndarray) -> np.ndarray:
        return ss.x[jc] + Qc @ (point - s0.x[jc])

    def axis(node: int, marker: str, col: int) -> np.ndarray:
        return st.R[node] @ model.marker_frames[marker][2][:, col]

    rigid = ("rear_", "carrier", "pinion_shaft")  # on the carrier, spins kept
    for name, i in model.node_index.items():
        if name.startswith(rigid):
            st.x[i] = carried(x0[i])
            st.R[i] = Qc @ R0[i]
        elif not name.startswith(("halfshaft_", "plunger_", "wheel_", "frame.body.")) \
                and name in ms.node_index:
            j = ms.node_index[name]  # the static displacement (the models may differ a little)
            st.x[i] = x0[i] + ss.x[j] - s0.x[j]
            st.R[i] = ss.R[j] @ s0.R[j].T @ R0[i]
    for name, i in model.node_index.items():  # the body's carriers: rigid with their node
        if name.startswith("frame.body.") and f"{name}.mount" in model.marker_frames:
            n = model.marker_frames[f"{name}.mount"][0]
            Qn = st.R[n] @ R0[n].T
            st.x[i] = st.x[n] + Qn @ (x0[i] - x0[n])
            st.R[i] = Qn @ R0[i]
    # the slip yoke turns about its axis so that the propeller shaft's rear joint to the
    # carried pinion stays square (the shaft's torsional spring takes the difference)
    sl = model.node_index["propshaft_slip"]
    k = axis(sl, "prop_slip_out", 2)
    u = axis(sl, "prop_slip_out", 0)
    v = axis(model.node_index["pinion_shaft"], "pinion_flange", 1)
    st.R[sl] = exp_so3(k * np.arctan(-(u @ v) / (np.cross(k, u) @ v))) @ st.R[sl]
    for w in WHEELS:  # the wheels turn with their uprights (their spins kept)
        wh = model.node_index[lay.wheels[w]]
        up = model.marker_frames[f"{lay.wheels[w]}_bearing_hub"][0]
        st.R[wh] = st.R[up] @ R0[up].T @ R0[wh]
        st.x[wh] = ss.x[ms.node_index[lay.wheels[w]]]
    for w in lay.drives:
        hs, pl, wh = (model.node_index[n] for n in (f"halfshaft_{w}", f"plunger_{w}",
                                                    lay.wheels[w]))
        p_in = x0[hs] + R0[hs] @ model.marker_frames[f"halfshaft_{w}_in"][1]
        p_in_new = carried(p_in)
        outer_new = st.x[wh] + (x0[pl] - x0[wh])
        a_old = Qc @ (x0[pl] - p_in) / np.linalg.norm(x0[pl] - p_in)
        a_new = (outer_new - p_in_new) / np.linalg.norm(outer_new - p_in_new)
        # with the carrier (the inner joint's cross stays square), then onto the wheel
        Q = _minimal_rotation(a_old, a_new) @ Qc
        st.x[hs] = p_in_new + Q @ (x0[hs] - p_in)
        st.R[hs] = Q @ R0[hs]
        st.x[pl] = outer_new
        st.R[pl] = Q @ R0[pl]
        # the wheel's spin angle that keeps the outer joint's cross square
        u = axis(pl, f"plunger_{w}_out", 0)
        k = st.R[wh][:, 2]
        v = axis(wh, f"halfshaft_{w}_wheel", 1)
        th = np.arctan2(-(u @ v), u @ np.cross(k, v))
        c, s_ = np.cos(th), np.sin(th)
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        st.R[wh] = (np.eye(3) + s_ * K + (1.0 - c) * K @ K) @ st.R[wh]
    if p.run.wind_up:
        st = wind_up(model, st, lay, p.solver.settings(h_max=p.run.h_max))
    return st
