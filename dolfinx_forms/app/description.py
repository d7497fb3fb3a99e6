"""A scene description of either kind, read and checked: single-step (scene_spec.py) or
multi-step (`method = "mpm"`, mpm_spec.py)."""

from dolfinx_forms.app import mpm_spec, scene_spec
from dolfinx_forms.common import SpecError

METHODS = ("single-step", "mpm")


def load(source, overrides=()):
    """The checked description (every default filled in) of a TOML file path or a dict, with
    the overrides ("a.b[1].c=VALUE") applied. Raises SpecError naming the first bad key."""
    data, base_dir, default_name = scene_spec.read(source, overrides)
    kind = data.get("method", "single-step") if isinstance(data, dict) else None
    if isinstance(data, dict) and kind not in METHODS:
        raise SpecError("method", f"must be one of {', '.join(map(repr, METHODS))}, got {kind!r}")
    validate = mpm_spec.validate if kind == "mpm" else scene_spec.validate
    return validate(data, base_dir=base_dir, default_name=default_name)
