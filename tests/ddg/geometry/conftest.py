"""Fixtures shared by the mesh tests of this folder: the gmsh mesh of the L x W strip, made once per
session (test_read_mesh.py reads it back from a file, test_gmsh_mesh.py checks it)."""
import time

import pytest

pytest.register_assert_rewrite("mesh_checks")   # its asserts report like the tests' own
from mesh_checks import L, W  # noqa: E402


@pytest.fixture(scope="session")
def gmsh_strip():
    pytest.importorskip("gmsh")
    from ddg.geometry.mesh_io import gmsh_mesh

    start = time.perf_counter()
    mesh = gmsh_mesh(L, W, 2000)
    return mesh, time.perf_counter() - start
