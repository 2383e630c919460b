"""``drivedyn report``: one self-contained HTML page about a run.

Sections (in this order, each an element with the id given in :data:`SECTIONS`): the model
summary (bodies, nodes, coordinates, multipliers, elements by type), the solver statistics
(integrator, steps, rejections, Newton iterations, factorizations, wall time), the energy
audit (energy terms at the end, balance error, the largest dissipators), the library model's
dashboard, the engineering plots, and the link to the 3-D view. Figures are embedded as PNG
(data URIs), so the page is one file that opens offline.
"""

from __future__ import annotations

import base64
import html
import io
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

#: section id -> heading
SECTIONS = {"model": "Model", "solver": "Solver statistics", "energy": "Energy audit",
            "dashboard": "Dashboard", "plots": "Engineering plots", "view": "3-D view"}


def _png(fig: Any) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _table(rows: list[tuple], head: tuple | None = None) -> str:
    out = ["<table>"]
    if head:
        out.append("<tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in head) + "</tr>")
    for r in rows:
        out.append("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _g(x: float, unit: str = "") -> str:
    if x is None or not np.isfinite(x):
        return "-"
    return f"{x:.4g} {unit}".strip()


def _model_section(ds: Any) -> str:
    raw = ds.attrs.get("model_summary")
    if raw is None:
        return "<p>This results file holds no model summary (written by an older drivedyn).</p>"
    s = json.loads(raw)
    rows = [("rigid bodies", s["bodies"]), ("nodes (beams, flexible parts)", s["nodes"]),
            ("coordinates (6 per body or node)", s["coordinates"]),
            ("constraint multipliers", s["multipliers"]), ("equations", s["equations"]),
            ("element internal states", s.get("internal_states", 0))]
    els = sorted(s["elements"].items(), key=lambda kv: -kv[1]["count"])
    erows = []
    for fam, e in els:
        names = ", ".join(e["names"][:8]) + (" ..." if len(e["names"]) > 8 else "")
        erows.append((fam, e["count"], names))
    source = ds.attrs.get("model_source", "")
    head = f"<p>Model <b>{html.escape(str(source))}</b></p>" if source else ""
    library = str(ds.attrs.get("library_model", ""))
    if library:
        rows = [("library model", library),
                ("configuration", str(ds.attrs.get("configuration", "")) or "-"), *rows]
    sets = json.loads(ds.attrs.get("overrides", "[]") or "[]")
    if sets:
        rows.append(("overrides (--set)", ", ".join(sets)))
    return head + _table(rows) + "<h3>Elements by type</h3>" + _table(
        erows, ("family", "count", "elements"))


def _solver_section(ds: Any) -> str:
    st = json.loads(ds.attrs.get("stats", "{}"))
    t = np.asarray(ds["time"].values, dtype=float)
    sim = float(t[-1] - t[0]) if len(t) else 0.0
    steps = st.get("steps", 0)
    rej = st.get("rejected", 0)
    its = st.get("newton_iterations", 0)
    wall = st.get("wall_s", float("nan"))
    rows = [("status", "completed" if int(ds.attrs.get("success", 1)) else
             f"stopped: {ds.attrs.get('message', '')}"),
            ("integrator", ds.attrs.get("integrator", "-")),
            ("Newton", ds.attrs.get("newton", "-")),
            ("step control", ds.attrs.get("step", "-")),
            ("simulated time", _g(sim, "s")),
            ("steps accepted", steps),
            ("steps rejected", f"{rej} ({100.0 * rej / max(steps + rej, 1):.1f} % of tried)"),
            ("Newton iterations", f"{its} ({its / max(steps, 1):.2f} per step)"),
            ("factorizations", st.get("factorizations", "-")),
            ("residual evaluations", st.get("residual_evaluations", "-")),
            ("smallest / largest step", f"{_g(st.get('h_min_used', np.nan), 's')} / "
                                        f"{_g(st.get('h_max_used', np.nan), 's')}"),
            ("wall time", _g(wall, "s")),
            ("wall time / simulated time", _g(wall / sim if sim > 0 else np.nan))]
    return _table(rows)


def _energy_section(ds: Any) -> str:
    def last(name: str) -> float:
        return float(ds[name].values[-1]) if name in ds and ds.sizes["time"] else float("nan")

    e0 = (float(ds["energy.kinetic"].values[0] + ds["energy.potential"].values[0])
          if "energy.kinetic" in ds else float("nan"))
    terms = [("kinetic energy T", last("energy.kinetic")),
             ("potential energy V", last("energy.potential")),
             ("initial T0 + V0", e0),
             ("work of loads", last("energy.work_loads")),
             ("work of drivers", last("energy.work_drivers")),
             ("work in W (loads + drivers)", last("energy.work_in")),
             ("dissipated D", last("energy.dissipated")),
             ("balance error (T + V) - (T0 + V0) - W + D", last("energy.balance_error"))]
    scale = max(abs(last("energy.work_in")), abs(last("energy.dissipated")),
                abs(last("energy.kinetic")), abs(e0), 1e-300)
    rel = abs(last("energy.balance_error")) / scale
    diss = [(str(v)[:-len(".dissipated_energy")], float(ds[v].values[-1]))
            for v in ds.data_vars if str(v).endswith(".dissipated_energy")]
    diss = sorted((d for d in diss if d[1] != 0.0), key=lambda d: -abs(d[1]))[:10]
    total = last("energy.dissipated")
    out = _table([(n, _g(v, "J")) for n, v in terms], ("term", "at the end"))
    out += (f"<p>Balance error relative to the largest term: <b>{rel:.2e}</b> "
            "(numerical dissipation of the integrator and constraint drift).</p>")
    if diss:
        out += "<h3>Largest dissipators</h3>" + _table(
            [(n, _g(v, "J"), f"{100 * v / total:.1f} %" if total else "-") for n, v in diss],
            ("element", "dissipated", "share"))
    return out


def _figures(figs: list[tuple[str, Any]]) -> str:
    return "\n".join(f'<figure><img alt="{html.escape(t)}" src="data:image/png;base64,'
                     f'{_png(f)}"><figcaption>{html.escape(t)}</figcaption></figure>'
                     for t, f in figs)


_STYLE = """
 body { font: 14px system-ui, sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }
 table { border-collapse: collapse; margin: 0.5em 0 1em; }
 td, th { border: 1px solid #ccc; padding: 3px 8px; text-align: left; vertical-align: top; }
 th { background: #f0f0f3; }
 figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
 figcaption { color: #555; font-size: 90%; }
 nav a { margin-right: 1em; }
"""


def write_report(ds: Any, out: str | os.PathLike, view: str | None = None) -> Path:
    """Write the report of results Dataset ``ds`` to ``out`` (HTML); ``view``: the 3-D view
    page to link (a path relative to the report), or None.

    Returns the path written.
    """
    import matplotlib

    matplotlib.use("Agg")
    from drivedyn.plots.engineering import dashboard_figures, engineering_figures

    title = str(ds.attrs.get("model_source") or "drivedyn run")
    dash = dashboard_figures(ds)
    body = {
        "model": _model_section(ds),
        "solver": _solver_section(ds),
        "energy": _energy_section(ds),
        "dashboard": _figures(dash) if dash else
        "<p>This run comes from no library model with a dashboard: see the engineering "
        "plots.</p>",
        "plots": _figures(engineering_figures(ds)),
        "view": (f'<p><a href="{html.escape(view)}">Open the 3-D view</a> (animated mechanism, '
                 "works offline).</p>") if view else
        "<p>No 3-D view was written (<code>drivedyn view RESULTS.nc</code> writes one).</p>",
    }
    nav = "".join(f'<a href="#{k}">{v}</a>' for k, v in SECTIONS.items())
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
             f"<title>{html.escape(title)} - drivedyn report</title><style>{_STYLE}</style>"
             f"</head><body><h1>{html.escape(title)}: run report</h1>"
             f"<p>drivedyn {html.escape(str(ds.attrs.get('drivedyn_version', '')))}</p>"
             f"<nav>{nav}</nav>"]
    for k, heading in SECTIONS.items():
        parts.append(f'<section id="{k}"><h2>{heading}</h2>{body[k]}</section>')
    parts.append("</body></html>")
    path = Path(out)
    tmp = path.with_name(path.name + ".part")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp.write_text("\n".join(parts), encoding="utf-8")
    os.replace(tmp, path)
    return path
