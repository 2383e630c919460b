"""The recorder stores only the variables a run asks for (``simulate(variables=...)``).

* A run that keeps a few variables gives them bit for bit as the run that keeps all, and the
  energy terms too (always recorded).
* What the compiled loop hands to the recorder has the selection's width, not the model's:
  the memory of a long run with dense outputs follows what is asked.
* Field variables of a flexible part (stresses on its mesh) come from the element's whole
  output row, kept as one block.
"""

from __future__ import annotations

import numpy as np
import pytest

import drivedyn as dd
from drivedyn.results import recorder as rc
from element_cases import contact, flexible


def _run(spec, variables, t_end=0.02, monkeypatch=None, widths=None):
    model = dd.compile_model(spec)
    if widths is not None:
        extend = rc.Recorder.extend

        def spy(self, t, x, Rm, v, aux, acc, diss, h):
            widths.append((x.shape[1], aux.shape[1], diss.shape[1]))
            return extend(self, t, x, Rm, v, aux, acc, diss, h)

        monkeypatch.setattr(rc.Recorder, "extend", spy)
    return dd.simulate(model, t_end, step=dd.FixedStep(1e-4), output_dt=1e-3,
                       variables=variables)


def test_selected_variables_equal_the_full_run(monkeypatch) -> None:
    """Journal contact case (two bodies, one contact): keeping ``B.position``, the contact's
    normal force and energy dissipated gives exactly the values of the run that keeps all,
    and the loop stores 1 node, 1 output entry and 1 element's energy per output (fails if
    the recorder stored everything, or picked the wrong entry of the output table)."""
    full = _run(contact.journal_case(), None)
    widths: list = []
    keep = ["B.position", "j.normal_force", "j.dissipated_energy"]
    part = _run(contact.journal_case(), keep, monkeypatch=monkeypatch, widths=widths)
    assert set(part.dataset.data_vars) == set(keep) | {
        k for k in full.dataset.data_vars if k.startswith(("energy.", "solver."))}
    for k in part.dataset.data_vars:
        np.testing.assert_array_equal(part.values(k), full.values(k), err_msg=k)
    assert widths and all(w == (1, 1, 1) for w in widths)


def test_angular_momentum_and_node_variables() -> None:
    """A rigid body's angular momentum (three output columns) and angular velocity (from the
    rotation and the velocities) are rebuilt from the stored entries."""
    keep = ["A.angular_momentum", "A.angular_velocity"]
    full = _run(contact.journal_case(), None)
    part = _run(contact.journal_case(), keep)
    for k in keep:
        np.testing.assert_array_equal(part.values(k), full.values(k), err_msg=k)


@pytest.mark.slow
def test_field_variables_of_a_flexible_washer() -> None:
    """The flexible washer contact's field variables (pressure on the face points) come from
    its whole output row: equal to the full run's."""
    full = _run(flexible.washer_case(), None, t_end=2e-3)
    fields = [k for k in full.dataset.data_vars if k.startswith("contact.")
              and full.dataset[k].ndim == 2 and "point" in full.dataset[k].dims[-1]]
    assert fields
    part = _run(flexible.washer_case(), [fields[0]], t_end=2e-3)
    np.testing.assert_array_equal(part.values(fields[0]), full.values(fields[0]))


def test_selection_of_everything_is_every_exported_output() -> None:
    """Without patterns every node, every exported output entry (not the hidden state
    columns a contact keeps in its output table) and every dissipative element is kept."""
    model = dd.compile_model(contact.journal_case())
    slices = rc._aux_slices(model)
    sel = rc.Selection(model, None, slices)
    assert sel.nodes.tolist() == list(range(model.nn))
    expected = set()
    for (off, shape), g in zip(slices, model.groups, strict=True):
        cols = [0, 1, 2] if g.family == "rigid_body" else [c for c, *_ in g.outputs()]
        expected |= {off + e * shape[1] + c for e in range(g.nel) for c in cols}
    assert set(sel.aux.tolist()) == expected and sel.aux.size < model.aux_all.size
    assert sel.diss.size == sum(g.nel for g in model.groups if g.dissipative)


def test_results_read_the_arrays_before_the_dataset_exists() -> None:
    """A run's results keep the recorded arrays and build the ``xarray.Dataset`` on first
    use: before it, ``values``, ``time``, ``in``, ``names()``, ``variables()`` and ``attrs``
    give what the dataset then holds (every variable bit for bit, units included; the names
    in the dataset's order, which the vehicle analyses' sums follow), and attributes written
    before (provenance) are the dataset's (fails if ``attrs`` handed out a copy, if
    ``names()`` built the dataset or listed the coordinates, or if the arrays and the
    dataset named or ordered variables differently)."""
    from drivedyn.results.provenance import record_provenance

    res = _run(contact.journal_case(), None)
    assert res._dataset is None
    early = {name: (dict(attrs), np.array(values)) for name, attrs, values in res.variables()}
    names = res.names()
    t = res.time.copy()
    assert "j.normal_force" in res and "time" in res and "nothing" not in res
    assert res._dataset is None
    record_provenance(res, model_file="{}", source="journal case")
    ds = res.dataset
    assert set(early) == set(ds.data_vars)
    assert names == [str(n) for n in ds.data_vars] == res.names()
    for name, (attrs, values) in early.items():
        np.testing.assert_array_equal(values, ds[name].values, err_msg=name)
        assert attrs["units"] == ds[name].attrs["units"], name
        np.testing.assert_array_equal(res.values(name), values, err_msg=name)
    np.testing.assert_array_equal(t, ds["time"].values)
    assert ds.attrs["model_source"] == "journal case" and res.attrs is ds.attrs
    assert ds.attrs["success"] == 1 and "stats" in ds.attrs
