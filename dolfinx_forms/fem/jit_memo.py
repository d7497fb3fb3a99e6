"""An in-process memo over DOLFINx's just-in-time compilation (`dolfinx.jit.ffcx_jit`).

Every `fem.FunctionSpace`, `fem.form` and `fem.Expression` asks FFCx for its compiled object.
FFCx finds it in its disk cache by a signature of the UFL object and the parameters, then
imports the cached module afresh: a scan of the cache folder (thousands of files after a while)
and a module import, about 2-3 ms per object. The material-point path builds a new mesh, and so
new spaces and forms, at every step (the Brazilian disc: 8 objects a step, ~0.8 s of a 50-step
run). This memo keeps what FFCx returned under the same key FFCx uses
(`ffcx.naming.compute_signature` of the object with the parameters), so a hit returns the very
objects a disk-cache hit would load (static data of one shared library, loaded once). A form's
integrals that differ in their subdomain id only (a law over 100 grains: one per grain) are
keyed by one of them and the ids (`_representatives`): as exact a key, at a tenth of the cost.
Objects FFCx keys otherwise (coordinate maps) pass through.

An interrupted compile leaves FFCx's claim on its module, the `.c` file in the cache, without
the `.c.cached` that says it is done: every later run that needs the object waited 10 s and
stopped with "JIT compilation timed out". FFCx renames the `.c` to `.c.failed` when a compile
raises an Exception; this module does the same
- for the modules this process claimed when the compile is interrupted otherwise (Ctrl-C,
  SystemExit, and SIGTERM, which raises SystemExit(143) during a compile: `_compile`);
- for a claim whose process is gone (SIGKILL, a crash: `_release_stale`): each claim of this
  process names its owner (host and pid) in a `.c.owner` file beside the `.c` until the compile
  ends; a claim whose owner is not running on this host, or an unnamed one unchanged for
  STALE_AGE, is released and the module compiled afresh. A live owner's claim is waited for
  as before.

Cell-integral ids from ALIAS_BASE on stand for a group of bodies (`fem.cut.CutIntegration`):
DOLFINx knows no cell of them, so a form holding them that is compiled other than by
`CutIntegration.form` (which hands the group's kernel to each body) raises here instead of
integrating over nothing.

`install()` wraps the process-local compiler under DOLFINx's MPI wrapper, which therefore stays
collective (rank 0 first, then the others) exactly as before. The application installs it at
start-up (`app.startup.start`); a script that uses the library alone may call `install()`.
"""

import contextlib
import functools
import os
import socket
import time
from pathlib import Path

from dolfinx_forms.common import signals_unwind

_memo = {}
# cell-integral ids from here on stand for a group of other ids (`fem.cut.CutIntegration.measure`)
# and mean nothing to DOLFINx: a form with them is compiled only inside `aliases_allowed`
# (`CutIntegration.form`, which hands the kernel to each id of the group)
ALIAS_BASE = 1 << 24
_aliases = [False]
_claimed = []  # the .c files of the modules this process is compiling (`_claims`)
# a claim without an owner file (FFCx alone, or an older version of this module) is taken for
# abandoned once its .c is this old (s): FFCx rewrites the .c with the module's source when it
# compiles, and the largest forms here compile in well under a minute
STALE_AGE = 3600.0


def _key(ufl_object, form_compiler_params, jit_params):
    """FFCx's own cache key of the object, or None for what this memo does not keep."""
    import ffcx.naming
    import ufl

    keep = isinstance(ufl_object, (ufl.Form, ufl.FiniteElementBase)) or (
        isinstance(ufl_object, tuple) and isinstance(ufl_object[0], ufl.core.expr.Expr)
    )
    if not keep:
        return None
    tag = repr((sorted(form_compiler_params.items()), sorted(jit_params.items())))
    if isinstance(ufl_object, ufl.Form):
        ufl_object, ids = _representatives(ufl_object)
        tag += repr(ids)
    return ffcx.naming.compute_signature([ufl_object], tag)


def _representatives(form):
    """(a form with one integral of each group of `form`'s integrals that differ in their
    subdomain id only, the ids of each group). The compiled form is a kernel per (integral
    type, id) made from the integrands of that id, so the representatives' signature and the
    groups' ids determine it: a key for FFCx's object as exact as the whole form's signature.
    Only cheaper: a bulk form of 100 grains of one law holds 200 integrals of 2 integrands, and
    its signature (a traversal of each integrand) cost 28 ms a step, this key 3 ms.
    Integrands are grouped by UFL's structural equality (the hash and operand-wise ==)."""
    import ufl

    groups = {}
    for itg in form.integrals():
        key = (itg.integrand(), itg.integral_type(), itg.ufl_domain(), repr(itg.metadata()))
        groups.setdefault(key, (itg, []))[1].append(itg.subdomain_id())
    if len(groups) == len(form.integrals()):
        return form, ()
    return ufl.Form([itg for itg, _ in groups.values()]), tuple(
        tuple(ids) for _, ids in groups.values()
    )


@contextlib.contextmanager
def aliases_allowed(allowed=True):
    """Compiles of forms with alias ids (ALIAS_BASE) allowed within (the caller expands them)."""
    before, _aliases[0] = _aliases[0], bool(allowed)
    try:
        yield
    finally:
        _aliases[0] = before


def _check_aliases(ufl_object):
    import ufl

    if _aliases[0] or not isinstance(ufl_object, ufl.Form):
        return
    for itg in ufl_object.integrals():
        i = itg.subdomain_id()
        if itg.integral_type() == "cell" and isinstance(i, int) and i >= ALIAS_BASE:
            raise RuntimeError(
                f"a cell integral on id {i}, which stands for a group of bodies (a cut scene's "
                "measure of several bodies): compile the form with CutIntegration.form, which "
                "gives the kernel to each body (fem.form would integrate over no cell)"
            )


def memoised(local_jit):
    """local_jit (the process-local `ffcx_jit`) with its results kept by FFCx's key. A form
    with alias ids compiled outside `aliases_allowed` raises (`_check_aliases`)."""

    @functools.wraps(local_jit)
    def jit(ufl_object, form_compiler_params={}, jit_params={}):
        _check_aliases(ufl_object)
        key = _key(ufl_object, form_compiler_params, jit_params)
        if key is None:
            return _compile(local_jit, ufl_object, form_compiler_params, jit_params)
        if key not in _memo:
            _memo[key] = _compile(local_jit, ufl_object, form_compiler_params, jit_params)
        return _memo[key]

    jit.memo = _memo
    return jit


def _compile(local_jit, *args):
    """local_jit(*args); interrupted by other than an Exception (Ctrl-C, SIGTERM), the modules it
    claimed and did not finish are marked failed, as FFCx marks those of a compile that raised.
    Their owner files go either way."""
    del _claimed[:]
    try:
        with signals_unwind():
            return local_jit(*args)
    except Exception:
        raise
    except BaseException:
        for c in _claimed:
            if c.exists() and not c.with_suffix(".c.cached").exists():
                os.replace(c, c.with_suffix(".c.failed"))
        raise
    finally:
        for c in _claimed:
            _remove(c.with_suffix(".c.owner"))
        del _claimed[:]


def _claims(get_cached_module):
    """FFCx's get_cached_module, recording the modules this process claims to compile (it
    returns (None, None) once it has created their .c file) with an owner file beside each, and
    releasing an abandoned claim first (`_release_stale`)."""

    @functools.wraps(get_cached_module)
    def claim(module_name, object_names, cache_dir, timeout):
        c = Path(cache_dir).joinpath(module_name).with_suffix(".c")
        _release_stale(c)
        found = get_cached_module(module_name, object_names, cache_dir, timeout)
        if found == (None, None):
            _claimed.append(c)
            c.with_suffix(".c.owner").write_text(f"{socket.gethostname()} {os.getpid()}\n")
        return found

    claim.claims = True
    return claim


def _release_stale(c):
    """Mark the claim `c` (a module's .c in FFCx's cache) failed if its compile was abandoned:
    not done (no .c.cached) and its owner (the .c.owner file: host and pid) not running on this
    host, or, without an owner file, the .c unchanged for STALE_AGE seconds. The next claim then
    compiles the module afresh, as after a compile that raised. A claim of another host, or of a
    running process, is left to FFCx's wait."""
    try:
        if c.with_suffix(".c.cached").exists():
            return
        age = c.stat().st_mtime
    except FileNotFoundError:
        return
    owner = c.with_suffix(".c.owner")
    try:
        host, pid = owner.read_text().split()
    except (FileNotFoundError, ValueError):
        if time.time() - age < STALE_AGE:
            return
    else:
        if host != socket.gethostname() or _running(int(pid)):
            return
    try:
        os.replace(c, c.with_suffix(".c.failed"))
    except FileNotFoundError:  # another process released it first
        pass
    _remove(owner)


def _running(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _remove(path):
    try:
        path.unlink()
    except FileNotFoundError:
        pass


def install():
    """Put the memo under `dolfinx.jit.ffcx_jit` (once per process; later calls do nothing)."""
    import ffcx.codegeneration.jit as ffcx_jit
    from dolfinx import jit

    if not getattr(ffcx_jit.get_cached_module, "claims", False):
        ffcx_jit.get_cached_module = _claims(ffcx_jit.get_cached_module)
    if getattr(jit.ffcx_jit, "memoised", False):
        return
    wrapped = jit.mpi_jit_decorator(memoised(jit.ffcx_jit.__wrapped__))
    wrapped.memoised = True
    jit.ffcx_jit = wrapped
