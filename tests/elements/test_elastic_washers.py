"""Thrust-washer contact stiffness from the washer's elastic properties (shared by the
differential models, :class:`drivedyn.library.differentials.schema_sections.ElasticWashers`).

Checks: the law's tangent at the rated load is the series stiffness of the washer layer and
the rough faces (central finite difference of the force law, independent of the closed form);
the penetration at the rated load is ``n (F t/(E S) + gamma h_rms)``; the two limits; the
models put the derived law on the washers only (pockets keep ``contact.stiffness``), and a
flexible washer's contact leaves out the layer its mesh already carries.
"""

from __future__ import annotations

import math

import pytest

from drivedyn.config import read_library_file
from drivedyn.config.loader import ModelFileError
from drivedyn.library.differentials import get
from drivedyn.library.differentials.scenarios import bench_spec
from drivedyn.library.differentials.schema_sections import Contact, elastic_washer_stiffness

RI, RE = 0.020, 0.030
AREA = math.pi * (RE**2 - RI**2)


def contact(**kw) -> Contact:
    return Contact.model_validate({"elastic_washers": {"enabled": True, **kw}})


@pytest.mark.parametrize("exponent", [1.0, 1.5, 2.0])
def test_tangent_at_rated_load_is_the_series_stiffness(exponent: float) -> None:
    c = contact(rated_load="1.8 kN")
    c = c.model_copy(update={"exponent": exponent})
    e = c.elastic_washers
    K = c.washer_law(RI, RE).stiffness
    delta = (e.rated_load / K) ** (1.0 / exponent)
    d = 1e-4 * delta
    tangent = (K * (delta + d) ** exponent - K * (delta - d) ** exponent) / (2 * d)
    h_rms = math.sqrt(2.0) * math.sqrt(math.pi / 2.0) * 0.4e-6
    series = 1.0 / (2e-3 / (206e9 * AREA) + 0.4 * h_rms / 1800.0)
    assert tangent == pytest.approx(series, rel=1e-7)
    # ground steel faces (Ra 0.4 um): a few tenths of a micrometre at the rated load
    assert delta == pytest.approx(exponent * (1800.0 * 2e-3 / (206e9 * AREA) + 0.4 * h_rms),
                                  rel=1e-12)


def test_limits_of_the_two_compliances() -> None:
    e = contact(rated_load=2000.0).elastic_washers
    # rough faces only (a flexible washer's mesh carries the layer): stiffer
    with_layer = elastic_washer_stiffness(e, RI, RE, 1.0)
    without = elastic_washer_stiffness(e, RI, RE, 1.0, layer=False)
    assert without > with_layer
    # smooth faces: the layer alone, E S / t for a linear law
    smooth = e.model_copy(update={"gamma": 1e-12})
    assert elastic_washer_stiffness(smooth, RI, RE, 1.0) == pytest.approx(
        206e9 * AREA / 2e-3, rel=1e-6)
    # disabled: the file's power law unchanged
    assert Contact().washer_law(RI, RE).stiffness == Contact().stiffness


def test_bad_values_name_the_key() -> None:
    with pytest.raises(ModelFileError, match=r"contact\.elastic_washers.*rated_load"):
        read_library_file("torsen-b", ["contact.elastic_washers.rated_load=\"-1 kN\""])
    with pytest.raises(ModelFileError, match=r"contact\.elastic_washers\.gamma"):
        read_library_file("torsen-b", ["contact.elastic_washers.gamma=0"])


@pytest.mark.parametrize("name, washer_family, washers", [
    ("torsen-b", "thrust_washer_contact", ("left", "middle", "right")),
    ("torsen-c", "thrust_washer_contact",
     ("sun_housing", "sun_coupling", "coupling_case", "ring_housing", "ring_case")),
])
def test_models_put_the_law_on_the_washers_only(name: str, washer_family: str,
                                                washers: tuple[str, ...]) -> None:
    p = read_library_file(name, ["contact.elastic_washers.enabled=true"])[0]
    spec = bench_spec(get(name), p, "right" if name == "torsen-b" else "rear")[0]
    seen = 0
    for el in spec.elements:
        law = getattr(el, "law", None)
        if law is None or el.family not in (washer_family, "journal_contact"):
            continue
        if el.name in washers:
            assert law.stiffness == pytest.approx(
                p.contact.washer_law(el.r_int, el.r_ext).stiffness, rel=1e-12)
            assert law.stiffness > 100 * p.contact.stiffness
            seen += 1
        else:       # pockets: bores and element end faces
            assert law.stiffness == p.contact.stiffness
    assert seen == len(washers)


def test_flexible_washer_contact_leaves_out_the_layer() -> None:
    p = read_library_file("torsen-c", ["contact.elastic_washers.enabled=true",
                                       "flexible.washers=true"])[0]
    spec = bench_spec(get("torsen-c"), p, "rear")[0]
    faces = [el for el in spec.elements if el.family == "flexible_washer_contact"]
    assert len(faces) == 5
    for el in faces:
        w = getattr(p.washers, el.name)
        assert el.law.stiffness == pytest.approx(
            p.contact.washer_law(w.r_int, w.r_ext, layer=False).stiffness, rel=1e-12)
