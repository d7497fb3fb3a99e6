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

`install()` wraps the process-local compiler under DOLFINx's MPI wrapper, which therefore stays
collective (rank 0 first, then the others) exactly as before. The application installs it at
start-up (`app.startup.start`); a script that uses the library alone may call `install()`.
"""

import functools

_memo = {}


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


def memoised(local_jit):
    """local_jit (the process-local `ffcx_jit`) with its results kept by FFCx's key."""

    @functools.wraps(local_jit)
    def jit(ufl_object, form_compiler_params={}, jit_params={}):
        key = _key(ufl_object, form_compiler_params, jit_params)
        if key is None:
            return local_jit(ufl_object, form_compiler_params, jit_params)
        if key not in _memo:
            _memo[key] = local_jit(ufl_object, form_compiler_params, jit_params)
        return _memo[key]

    jit.memo = _memo
    return jit


def install():
    """Put the memo under `dolfinx.jit.ffcx_jit` (once per process; later calls do nothing)."""
    from dolfinx import jit

    if getattr(jit.ffcx_jit, "memoised", False):
        return
    wrapped = jit.mpi_jit_decorator(memoised(jit.ffcx_jit.__wrapped__))
    wrapped.memoised = True
    jit.ffcx_jit = wrapped
