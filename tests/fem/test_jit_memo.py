"""The in-process memo over DOLFINx's JIT (fem/jit_memo.py): one compiled object per FFCx key,
reused across meshes, and never shared by forms that differ (different constants, spaces,
quadrature degrees). Also under mpirun -n 2: the memo sits under DOLFINx's collective wrapper."""

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem, jit, la, mesh as dmesh
from mpi4py import MPI

from dolfinx_forms.fem import jit_memo


def _square(n, side):
    return dmesh.create_rectangle(
        MPI.COMM_WORLD, [[0.0, 0.0], [side, side]], [n, n], dmesh.CellType.quadrilateral
    )


def _total(form):
    return MPI.COMM_WORLD.allreduce(fem.assemble_scalar(form), op=MPI.SUM)


def test_one_compiled_object_per_key_and_the_right_values():
    jit_memo.install()
    jit_memo.install()  # idempotent: one memo layer
    layer = jit.ffcx_jit.__wrapped__  # the memo, under DOLFINx's MPI wrapper
    assert jit.ffcx_jit.memoised and hasattr(layer, "memo")
    assert not hasattr(layer.__wrapped__, "memo")
    memo = jit_memo._memo

    # the same element on two meshes: one entry, the same compiled element
    m1, m2 = _square(4, 1.0), _square(7, 2.0)
    V1 = fem.FunctionSpace(m1, ("Lagrange", 1))
    n = len(memo)
    V2 = fem.FunctionSpace(m2, ("Lagrange", 1))
    assert len(memo) == n and V2._ufcx_element is V1._ufcx_element
    # an element no other test compiles (a CutIntegration installs the memo, so earlier tests
    # of the process may have filled it)
    fem.FunctionSpace(m2, ("Lagrange", 5))
    assert len(memo) == n + 1

    # the same form on two meshes: one compiled form, each mesh's own integral
    def area_form(m, c):
        return fem.form(c * ufl.dx(domain=m))

    n = len(memo)
    assert np.isclose(_total(area_form(m1, 2.0)), 2.0)
    assert np.isclose(_total(area_form(m2, 2.0)), 8.0)
    assert len(memo) == n + 1
    # a different constant (baked into the kernel) or quadrature degree: a new entry and value
    assert np.isclose(_total(area_form(m2, 3.0)), 12.0)
    assert len(memo) == n + 2
    x = ufl.SpatialCoordinate(m2)
    md = {"quadrature_degree": 1}
    # int_0^2 int_0^2 x^4 dy dx = 2 * 32 / 5; degree 1 integrates x^4 inexactly
    exact = fem.form(x[0] ** 4 * ufl.dx(domain=m2))
    rough = fem.form(x[0] ** 4 * ufl.dx(domain=m2, metadata=md))
    assert np.isclose(_total(exact), 64.0 / 5.0)
    assert not np.isclose(_total(rough), 64.0 / 5.0, rtol=1e-3)

    # a linear form with a coefficient, on the spaces of two meshes: each mesh's mass
    for V, area in ((V1, 1.0), (V2, 4.0)):
        ones, v = fem.Function(V), ufl.TestFunction(V)
        ones.x.array[:] = 1.0
        b = fem.assemble_vector(fem.form(ones * v * ufl.dx))
        b.scatter_reverse(la.ScatterMode.add)
        owned = b.array[: V.dofmap.index_map.size_local].sum()
        assert np.isclose(MPI.COMM_WORLD.allreduce(owned, op=MPI.SUM), area)


@pytest.mark.mpi
def test_one_compiled_object_per_key_on_two_ranks():
    test_one_compiled_object_per_key_and_the_right_values()


def test_forms_over_many_ids_keyed_by_their_groups():
    # integrals that differ in their subdomain id only are keyed by one representative and the
    # ids of each group: the same structure on another mesh hits, any other grouping misses
    jit_memo.install()
    memo = jit_memo._memo

    def tagged(n):  # cells tagged 1, 2, 3 by column thirds of the unit square
        m = _square(n, 1.0)
        nc = m.topology.index_map(2).size_local + m.topology.index_map(2).num_ghosts
        x = dmesh.compute_midpoints(m, 2, np.arange(nc, dtype=np.int32))[:, 0]
        tags = dmesh.meshtags(m, 2, np.arange(nc, dtype=np.int32),
                              (1 + np.minimum(3 * x, 2)).astype(np.int32))  # fmt: skip
        return m, ufl.Measure("dx", domain=m, subdomain_data=tags)

    def total(dx, a_ids, b_ids, deg=2):
        x = ufl.SpatialCoordinate(dx.ufl_domain())
        form = sum(x[0] ** deg * dx(i) for i in a_ids) + sum(7.0 * dx(i) for i in b_ids)
        return _total(fem.form(form))

    def exact(a_ids, b_ids):  # int of x^2 and of 7 over the thirds
        third = [((k + 1) ** 3 - k**3) / 81.0 for k in range(3)]
        return sum(third[i - 1] for i in a_ids) + sum(7.0 / 3.0 for _ in b_ids)

    (_, dx1), (_, dx2) = tagged(6), tagged(9)
    n = len(memo)
    assert np.isclose(total(dx1, (1, 2), (3,)), exact((1, 2), (3,)))
    assert len(memo) == n + 1
    assert np.isclose(total(dx2, (1, 2), (3,)), exact((1, 2), (3,)))  # another mesh: a hit
    assert len(memo) == n + 1
    for a_ids, b_ids in (((1,), (2, 3)), ((1, 2), (1,)), ((1, 2), (2,)), ((1, 2, 3), ())):
        assert np.isclose(total(dx2, a_ids, b_ids), exact(a_ids, b_ids))
    assert len(memo) == n + 5
    # an integrand that differs (x^3) with the same ids: a new entry
    assert not np.isclose(total(dx2, (1, 2), (3,), deg=3), exact((1, 2), (3,)))
    assert len(memo) == n + 6


def test_an_interrupted_compile_leaves_no_claim(tmp_path, monkeypatch):
    """A compile interrupted by Ctrl-C (KeyboardInterrupt inside FFCx's compiler) leaves its
    module's .c marked failed, as FFCx marks a compile that raised: the next request compiles
    it again instead of waiting for the interrupted one and timing out (FFCx's "JIT
    compilation timed out", after `timeout` seconds; a fresh cache folder here)."""
    import ffcx.codegeneration.jit as ffcx_jit

    jit_memo.install()
    m = _square(2, 1.0)
    x = ufl.SpatialCoordinate(m)
    a = (x[0] + 2.0 * x[1]) * ufl.dx
    params = {"cache_dir": str(tmp_path), "timeout": 2}

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    with monkeypatch.context() as patch:
        patch.setattr(ffcx_jit, "_compile_objects", interrupted)
        with pytest.raises(KeyboardInterrupt):
            fem.form(a, jit_params=params)
    assert list(tmp_path.glob("*.c")) == [] and len(list(tmp_path.glob("*.c.failed"))) == 1
    assert np.isclose(_total(fem.form(a, jit_params=params)), 1.5)  # int x + 2 y = 1/2 + 1


def _claim_test_form():
    m = _square(2, 1.0)
    x = ufl.SpatialCoordinate(m)
    return (x[0] + 2.0 * x[1]) * ufl.dx


def _claims_of(tmp_path, a):
    """The .c files (FFCx's module claims) of form `a`'s modules, from a compile in a cache of
    their own."""
    seen = tmp_path / "seen"
    fem.form(a, jit_params={"cache_dir": str(seen), "timeout": 2})
    return sorted(p.name for p in seen.glob("*.c"))


def test_an_abandoned_claim_is_compiled_afresh(tmp_path):
    """A claim left by a process that is gone (killed by SIGKILL, crashed: its .c without the
    .c.cached of a finished compile) is released and the module compiled afresh, whether its
    owner file names a process that no longer runs or, without one, it is older than
    STALE_AGE. A claim of a running process, or a fresh unnamed one, is waited for as FFCx does
    (and times out here after `timeout` seconds)."""
    jit_memo.install()
    a = _claim_test_form()
    names = _claims_of(tmp_path, a)
    assert names
    gone = subprocess.Popen(["true"])
    gone.wait()  # its pid names no running process (a reused pid would only mean a wait)
    live = subprocess.Popen(["sleep", "60"])
    host = socket.gethostname()
    try:
        cases = {
            "gone": (f"{host} {gone.pid}", 0.0, True),
            "old": (None, 2 * jit_memo.STALE_AGE, True),
            "live": (f"{host} {live.pid}", 0.0, False),
            "fresh": (None, 0.0, False),
        }
        for name, (owner, age, released) in cases.items():
            cache = tmp_path / name
            cache.mkdir()
            for n in names:
                c = cache / n
                c.touch()
                os.utime(c, (time.time() - age,) * 2)
                if owner:
                    c.with_suffix(".c.owner").write_text(owner + "\n")
            params = {"cache_dir": str(cache), "timeout": 2}
            if released:
                assert np.isclose(_total(fem.form(a, jit_params=params)), 1.5), name
                assert len(list(cache.glob("*.c.cached"))) == len(names), name
                assert list(cache.glob("*.c.owner")) == [], name
            else:
                with pytest.raises(TimeoutError):
                    fem.form(a, jit_params=params)
    finally:
        live.kill()
        live.wait()


SIGTERM_SCRIPT = """
import os, signal, sys, time
import ffcx.codegeneration.jit as ffcx_jit
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from dolfinx_forms.fem import jit_memo

jit_memo.install()

def terminated(*args, **kwargs):
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(30)

ffcx_jit._compile_objects = terminated
m = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2, mesh.CellType.quadrilateral)
x = ufl.SpatialCoordinate(m)
fem.form((x[0] + 3.0 * x[1]) * ufl.dx, jit_params={"cache_dir": sys.argv[1]})
"""


def test_a_compile_ended_by_sigterm_leaves_no_claim(tmp_path):
    """SIGTERM during a compile (mpirun ending its ranks, a batch system's time limit) ends the
    process with status 143 and marks the module's claim failed, its owner file removed, as
    Ctrl-C does: the next run compiles it instead of timing out."""
    cache = tmp_path / "cache"
    env = {**os.environ, "PYTHONPATH": str(Path(jit_memo.__file__).parents[2])}
    run = subprocess.run(
        [sys.executable, "-c", SIGTERM_SCRIPT, str(cache)], env=env, capture_output=True,
        text=True, timeout=120,
    )  # fmt: skip
    assert run.returncode == 143, run.stderr[-2000:]
    assert list(cache.glob("*.c")) == [] and list(cache.glob("*.c.owner")) == []
    assert len(list(cache.glob("*.c.failed"))) == 1
