"""A part's geometric data kept on disk (:mod:`drivedyn.fe.disk_cache`): what comes back from
the cache is what was computed, a damaged entry is computed again, and the scikit-fem mesh
built without meshio is the one its meshio reader builds."""

from __future__ import annotations

import numpy as np
import pytest

from drivedyn import settings
from drivedyn.fe import SolidMaterial, SolidModel, annular_washer, annulus_quadrature
from drivedyn.fe.mesh import SolidMesh
from small_models import tet_box


@pytest.fixture
def cache(tmp_path):
    """An empty cache folder for the test (the settings restored after it)."""
    before = settings.current()
    settings.configure(cache_dir=tmp_path)
    yield tmp_path / "fe"
    settings._current = before


@pytest.mark.parametrize("mesh", [annular_washer(0.02, 0.03, 0.002, 2, 12, 1),
                                  tet_box(0.1, 0.02, 3, 1)],
                         ids=["hexahedra", "tetrahedra"])
def test_the_scikit_fem_mesh_is_the_one_of_its_meshio_reader(mesh):
    """Vertices and cells (vertex order included) equal those of
    ``skfem.io.meshio.from_meshio``. Fails with the hexahedra's vertices in VTK order
    (``HEX_TO_SKFEM`` the identity)."""
    import meshio
    from skfem.io.meshio import from_meshio

    cell_type = "hexahedron" if mesh.kind == "hex" else "tetra"
    ref = from_meshio(meshio.Mesh(mesh.points, [(cell_type, mesh.cells)]))
    sk = SolidModel(mesh, SolidMaterial())._skmesh
    assert type(sk) is type(ref)
    np.testing.assert_array_equal(sk.p, ref.p)
    np.testing.assert_array_equal(sk.t, ref.t)


def test_face_areas_and_point_values_come_back_from_the_cache(cache, monkeypatch):
    """The second call reads the entry the first wrote (the computation is then not run: it
    raises here) and gives the same arrays bit for bit; other points are another entry; a
    damaged entry is computed again. Fails if the entry's key leaves out the points (the
    second set of points would get the first's values) or if a damaged entry is read."""
    solid = SolidModel(annular_washer(0.02, 0.03, 0.002, 2, 12, 1), SolidMaterial())
    face = solid.select("z", 0.002)
    pts, _ = annulus_quadrature(0.02, 0.03, 0.002, 2, 6, cells=2)
    areas = solid.face_areas(face)
    P = solid.interpolation(pts)
    assert len(list(cache.glob("face_areas-*.npz")) + list(cache.glob("interpolation-*.npz"))) \
        == 2

    def refused(*args):
        raise AssertionError("computed again")

    with monkeypatch.context() as m:
        m.setattr(SolidModel, "_face_areas", refused)
        m.setattr(SolidModel, "_interpolation", refused)
        np.testing.assert_array_equal(solid.face_areas(face), areas)
        again = solid.interpolation(pts)
        assert again.shape == P.shape
        np.testing.assert_array_equal(again.toarray(), P.toarray())
    other = solid.interpolation(pts[:5] * [1.0, 1.0, 0.5])
    assert not np.array_equal(other.toarray(), P[:5].toarray())
    np.testing.assert_allclose(other.sum(axis=1), 1.0, rtol=1e-12)   # a partition of unity
    for f in cache.glob("face_areas-*.npz"):
        f.write_bytes(b"not an npz file")
    np.testing.assert_array_equal(solid.face_areas(face), areas)


def test_a_mesh_seen_before_builds_no_scikit_fem_object(cache):
    """The nodes of a mesh seen before come from the cache folder, equal bit for bit, and the
    scikit-fem mesh and bases are not built until used; a mesh that fails the orientation
    check is not cached, so it fails again. Fails if the nodes are cached before the check
    (the second construction of the inverted mesh would pass) or if the bases are built in
    the constructor."""
    from drivedyn.errors import ModelError

    mesh = annular_washer(0.02, 0.03, 0.002, 2, 12, 1)
    first = SolidModel(mesh, SolidMaterial())
    second = SolidModel(mesh, SolidMaterial())
    np.testing.assert_array_equal(second.nodes, first.nodes)
    assert not {"_skmesh", "_sbasis", "_vbasis"} & set(second.__dict__)
    face = first.select("z", 0.002)
    np.testing.assert_array_equal(second.face_areas(face), first.face_areas(face))
    cells = mesh.cells.copy()
    cells[1] = cells[1][[4, 5, 6, 7, 0, 1, 2, 3]]          # one cell turned inside out
    bad = SolidMesh(mesh.points, cells, "hex")
    for _ in range(2):
        with pytest.raises(ModelError, match="inverted or degenerate"):
            SolidModel(bad, SolidMaterial())


def test_another_scikit_fem_version_reads_other_entries(cache, monkeypatch):
    """The entries' key holds scikit-fem's installed version (its node numbering could
    change with it): the same computation under another version is another file. Fails if
    the version is left out of the key."""
    from drivedyn.fe import disk_cache

    here = disk_cache.entry("nodes", (b"mesh",))
    assert disk_cache._computed_by().startswith(f"{disk_cache.CACHE_VERSION}/scikit-fem ")
    monkeypatch.setattr(disk_cache, "_computed_by", lambda: "1/scikit-fem 0.0.1")
    assert disk_cache.entry("nodes", (b"mesh",)) != here
