"""Verification scenes for the contact code: gmsh-built (Hertz also gmsh-free, in layers:
`layers.py`), multi-body DOLFINx meshes.

Each generator returns a :class:`Scene` (one mesh holding all bodies, disjoint, with body
cell tags, named boundary facet tags, exact signed-distance shapes and contact pairs).
gmsh runs on rank 0 only; call the generators collectively on `comm`:

    from meshes import hertz_scene, two_blocks_scene, incline_scene, patch_scene
"""

from dolfinx_forms.mesh.scene import (  # noqa: F401
    Body,
    Scene,
    gmsh_model,
    scene_from_arrays,
    scene_from_gmsh,
    summary,
)

_GENERATORS = {
    "hertz_scene": "hertz",
    "hertz_contact_box": "hertz",
    "two_blocks_scene": "two_blocks",
    "incline_scene": "incline",
    "patch_scene": "patch",
}
__all__ = [
    "Body",
    "Scene",
    "gmsh_model",
    "scene_from_arrays",
    "scene_from_gmsh",
    "summary",
    *_GENERATORS,
]


def __getattr__(name):
    """Lazy generator imports, so `python3 -m meshes.hertz` runs without a runpy warning."""
    if name in _GENERATORS:
        import importlib

        return getattr(importlib.import_module(f".{_GENERATORS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
