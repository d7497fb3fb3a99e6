"""Scenes: several bodies on one DOLFINx mesh with body cell tags, named boundaries and exact
level-set shapes (`scene`), on cut structured grids (`cut_scene`), or from a scene
description (`from_spec`). The verification scenes themselves live in the `meshes` package."""
