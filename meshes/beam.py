"""A rectangular beam on a structured body-fitted mesh, clamped at its left end (the
cantilever demo): a one-body description built by the description machinery."""

from __future__ import annotations


def cantilever_scene(comm, length=16.0, height=0.8, h=0.2, quads=True):
    """Scene of [0, length] x [0, height] (body "beam", tag 1) with cells of size about h and
    the boundary "clamp" at x = 0."""
    from dolfinx_forms.app.description import load
    from dolfinx_forms.mesh.from_spec import build_scene

    spec = load(
        {
            "name": "cantilever",
            "discretization": {"kind": "fitted", "h": float(h), "structured": True,
                               "cell": "quadrilateral" if quads else "triangle"},
            "bodies": [{"name": "beam", "shape": {"type": "box", "min": [0.0, 0.0],
                        "max": [float(length), float(height)]},
                        "law": {"type": "linear", "E": 1.0, "nu": 0.3}}],
            "boundaries": [{"name": "clamp", "body": "beam", "side": "left"}],
            "dirichlet": [{"name": "clamp", "boundary": "clamp"}],
        }
    )  # fmt: skip
    return build_scene(comm, spec)
