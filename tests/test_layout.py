"""The package layout follows the data flow: stages import only earlier stages.

Imports are read from the source (module level, inside functions, under TYPE_CHECKING):
no import cycle among the modules, no arrow from a stage to a later one, and imports
inside functions only for the optional dependencies.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "laplace_springs"

#: Stages in data-flow order; a module may import only its own stage or earlier ones.
STAGES = ("_version", "limits", "kernels", "model", "exact", "numeric", "analysis", "output",
          "policy", "planning", "solution",
          "routes", "solving", "sweeps", "publish", "bench", "cli", "__init__", "__main__")
#: Third-party packages imported where used: the optional ones, and SciPy (a core dependency,
#: but its submodules take up to a second to import, so only the routes that need them do).
OPTIONAL = {"matplotlib", "scipy", "control", "dask", "distributed", "nbclient", "nbformat", "pint",
            "ipywidgets", "IPython", "mathjax", "PIL", "imageio_ffmpeg"}
#: Modules of the package imported inside a function on purpose: the command line loads the
#: stages of its heavier subcommands (the benchmark's peers, the publish pages and
#: animations) only when they run, so ``laplace-springs solve`` starts without them.
DEFERRED = {("laplace_springs.cli", "laplace_springs.bench.harness"),
            ("laplace_springs.cli", "laplace_springs.publish.commands")}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _stage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _imports(path: Path) -> list[tuple[str, bool, int]]:
    """(imported laplace_springs module or third-party top name, inside a function, line)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = _module_name(path) if path.name == "__init__.py" else _module_name(path).rpartition(".")[0]
    inside: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            inside |= {id(sub) for sub in ast.walk(node) if isinstance(sub, (ast.Import, ast.ImportFrom))}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, id(node) in inside, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
                names = [f"{target}.{alias.name}" for alias in node.names]
                found += [(name, id(node) in inside, node.lineno) for name in names]
            else:
                found.append((node.module or "", id(node) in inside, node.lineno))
    return found


def _graph() -> dict[str, set[str]]:
    modules = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        for imported, _, _ in _imports(path):
            target = imported
            while target and target not in modules:  # "pkg.module.name" -> "pkg.module"
                target = target.rpartition(".")[0]
            if target and target != name and target != "laplace_springs":
                graph[name].add(target)
    return graph


def test_there_is_no_import_cycle():
    graph = _graph()
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])


def test_stages_import_only_earlier_stages():
    arrows = [(a, b) for a, targets in _graph().items() for b in targets
              if STAGES.index(_stage(b)) > STAGES.index(_stage(a))]
    assert not arrows, f"imports that run back up the data flow: {arrows}"


def test_imports_inside_functions_are_optional_dependencies():
    offending = [f"{path.relative_to(PACKAGE.parent)}:{line}: {name}"
                 for path in PACKAGE.rglob("*.py") for name, inside, line in _imports(path)
                 if inside and name.split(".")[0] not in OPTIONAL
                 and not {(_module_name(path), name),
                          (_module_name(path), name.rpartition(".")[0])} & DEFERRED]
    assert not offending, offending


def test_the_scene_is_a_data_object():
    source = (PACKAGE / "model" / "scene.py").read_text(encoding="utf-8")
    assert "def modes(" not in source
    # Scene.draw is a thin alias of output.drawing.draw_scene, reached through a hook
    body = source.split("    def draw(", 1)[1].split("\n    def ", 1)[0]
    assert "return _drawer()(self, ax, **options)" in body and len(body.splitlines()) <= 4
