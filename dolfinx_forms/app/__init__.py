"""The application on top of the library and the scene builders: the command line (`cli`),
scene descriptions (`scene_spec`, `runner`), the run skeleton of the demos (`demo`,
`mpm_run`), convergence studies (`study`), and the process start-up (`startup`), which
importing this package performs once.

`dolfinx_forms.run(scene)` and `python3 -m dolfinx_forms run scene.toml` build the scene with
`dolfinx_forms.mesh.from_spec.build_scene`.
"""

from dolfinx_forms.app import startup as _startup

_startup.start()


def run(source, out=None, **kwargs):
    """`runner.run` with the scene builder of `dolfinx_forms.mesh.from_spec` (see runner.run)."""
    from dolfinx_forms.app.runner import run as run_description
    from dolfinx_forms.mesh.from_spec import build_scene

    kwargs.setdefault("build_scene", build_scene)
    return run_description(source, out, **kwargs)
