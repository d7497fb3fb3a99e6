"""The application layer: run a scene description with the repository's scene builders.

The library modules never import `meshes` (scenes use the library, never the reverse). This
module and `__main__` are the application on top of both: `dolfinx_forms.run(scene)` and
`python3 -m dolfinx_forms run scene.toml` pass `meshes.from_spec.build_scene` to
`runner.run`, importing it when called.
"""


def run(source, out=None, **kwargs):
    """`runner.run` with the scene builder of the `meshes` package (see runner.run)."""
    from meshes.from_spec import build_scene

    from .runner import run as run_description

    kwargs.setdefault("build_scene", build_scene)
    return run_description(source, out, **kwargs)
