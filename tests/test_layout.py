"""The structure of the package (issue 28): the import graph of `dolfinx_forms` and `meshes`
read from the source (every import statement, at module level or inside a function), and what
`import dolfinx_forms` does to the process.

* no import cycle among the modules of dolfinx_forms, nor among those of meshes;
* dolfinx_forms never imports meshes, demos or benchmarks (scenes use the library, never the
  reverse; nothing installed reads the repository's scripts);
* only the application (`dolfinx_forms.app`, `dolfinx_forms.__main__`) imports the
  application: the library's sub-packages never import `dolfinx_forms.app` (the package's
  `dolfinx_forms.run`, which runs a scene description, imports it on first use);
* `import dolfinx_forms` changes no environment variable and starts no process.
"""

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def module_name(path):
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules(package):
    return {module_name(f): f for f in sorted((ROOT / package).rglob("*.py"))}


def imports(path, name):
    """The dotted names that the module at `path` (module `name`) imports, relative imports
    resolved; `from a import b` gives a.b when a.b is a module, else a."""
    is_pkg = path.name == "__init__.py"
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = name.split(".") if is_pkg else name.split(".")[:-1]
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)
    return out


def graph(package):
    mods = modules(package)
    return {m: {i for i in imports(f, m) if i in mods and i != m} for m, f in mods.items()}


def cycles(g):
    """The strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in g[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return out


def without_package_parents(g):
    """Importing a.b.c runs a/__init__ and a/b/__init__: those edges are implied, not cycles
    of the design; a package's __init__ importing its own modules is not a cycle either."""
    return {
        m: {i for i in deps if not m.startswith(i + ".") and not i.startswith(m + ".")}
        for m, deps in g.items()
    }


def test_graph_reader_sees_imports_and_cycles():
    g = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(g) == [["a", "b", "c"]]
    path = ROOT / "dolfinx_forms" / "solvers" / "problem.py"
    deps = imports(path, "dolfinx_forms.solvers.problem")
    assert "dolfinx_forms.fem.bulk" in deps and "dolfinx_forms.solvers.newton" in deps


def test_no_import_cycle():
    for package in ("dolfinx_forms", "meshes"):
        g = without_package_parents(graph(package))
        assert len(g) > 10
        assert cycles(g) == [], f"import cycles in {package}"


def test_library_imports_neither_scenes_nor_scripts():
    bad = [
        (m, i)
        for m, f in modules("dolfinx_forms").items()
        for i in imports(f, m)
        if i.split(".")[0] in ("meshes", "demos", "benchmarks", "tests")
    ]
    assert bad == []


LAZY_RUN = {"dolfinx_forms.app", "dolfinx_forms.app.run"}  # dolfinx_forms.__getattr__("run")


def test_only_the_application_imports_the_application():
    bad = [
        (m, i)
        for m, f in modules("dolfinx_forms").items()
        if not (m.startswith("dolfinx_forms.app") or m == "dolfinx_forms.__main__")
        for i in imports(f, m) - (LAZY_RUN if m == "dolfinx_forms" else set())
        if i == "dolfinx_forms.app" or i.startswith("dolfinx_forms.app.")
    ]
    assert bad == [], "library modules importing the application layer"


PROBE = """
import json, os, sys
before = dict(os.environ)
mods = set(sys.modules)
import dolfinx_forms
after = dict(os.environ)
children = []
for task in os.listdir("/proc/self/task"):
    with open(f"/proc/self/task/{task}/children") as f:
        children += f.read().split()
print(json.dumps(dict(
    changed=sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k)),
    children=children,
    app=[m for m in sys.modules if m.startswith("dolfinx_forms.app")],
    heavy=[m for m in ("mpi4py.MPI", "ufl", "ffcx", "matplotlib")
           if m in sys.modules and m not in mods],
)))
"""


def test_import_has_no_side_effects(tmp_path):
    """In a fresh interpreter started from a demo's folder name (the early plot worker's
    trigger): no environment variable changed, no child process, the application not
    imported, and neither MPI, UFL, FFCx nor matplotlib loaded."""
    demos = tmp_path / "demos"
    demos.mkdir()
    script = demos / "probe.py"
    script.write_text(PROBE)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout.strip().splitlines()[-1])
    assert got == dict(changed=[], children=[], app=[], heavy=[])


def test_tests_mirror_the_packages():
    """Each sub-package of dolfinx_forms has its folder of tests (tests/<sub-package>/), and
    no test module sits loose at the top but the structure, install and binding checks."""
    package = ROOT / "dolfinx_forms"
    subs = sorted(p.name for p in package.iterdir() if (p / "__init__.py").exists())
    assert subs and all((ROOT / "tests" / s).is_dir() for s in subs), subs
    loose = sorted(p.name for p in (ROOT / "tests").glob("test_*.py"))
    assert loose == ["test_bindings.py", "test_install.py", "test_layout.py"]
