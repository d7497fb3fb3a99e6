"""Run under `mpirun -n 2` (make test-mpi): the geometry core is rank-local, so points
split over ranks must give bitwise the projections and contact surface of one rank."""

import numpy as np
import pytest

import dolfinx_forms as df

mpi4py = pytest.importorskip("mpi4py")
from mpi4py import MPI  # noqa: E402

pytestmark = pytest.mark.mpi


def test_two_ranks_match_serial_bitwise():
    comm = MPI.COMM_WORLD
    assert comm.size == 2, "this test is meant for mpirun -n 2"
    g = df.StructuredGrid.uniform([-2, -2], [2, 2], [80, 80])
    phi = df.levelset_from_shape(g, df.Ellipse([0.1, 0.0], 1.2, 0.6, 0.3))
    rng = np.random.default_rng(7)
    pts = rng.uniform(-1.8, 1.8, (1001, 2))
    serial = df.closest_point_projection(phi, pts)
    mine = np.array_split(np.arange(len(pts)), comm.size)[comm.rank]
    local = df.closest_point_projection(phi, pts[mine])
    gathered = np.concatenate(comm.allgather(local["points"]))
    status = np.concatenate(comm.allgather(local["status"]))
    assert np.array_equal(gathered, serial["points"])
    assert np.array_equal(status, serial["status"])

    a = df.levelset_from_shape(g, df.Circle([-0.6, 0.0], 0.55))
    b = df.levelset_from_shape(g, df.Circle([0.6, 0.0], 0.6))
    s = df.contact_surface(a, b, eps=0.1)
    other = comm.bcast(s["points"], root=0)
    assert len(s["weights"]) > 0 and np.array_equal(other, s["points"])
