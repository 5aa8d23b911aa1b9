"""The import graph of ``python/tcsim``: no cycles, and imports go down the layers only.

Layers, lowest first (a module may import its own layer's modules and any lower layer; io, plots
and reports are one layer and do not import each other; the command line and the public facades
are the top):

0. ``tcsim._core``, ``tcsim.errors``, ``tcsim.units`` (the base any module may import)
1. ``tcsim.models``
2. ``tcsim.simulation``
3. ``tcsim.analysis``
4. ``tcsim.io`` | ``tcsim.plots`` | ``tcsim.reports`` (siblings: none imports another)
5. ``tcsim.cli``
6. the package itself, ``tcsim.__main__`` and the facades of documented paths
   (``tcsim.transient``, ``tcsim.replay``, ``tcsim.fmu``, ...)

Module-level and function-level imports count alike, relative and absolute.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "python" / "tcsim"

#: (rank, group) of each top-level part of the package; anything not listed is a facade (rank 6).
LAYERS: dict[str, tuple[int, str]] = {
    "_core": (0, "base"),
    "errors": (0, "base"),
    "units": (0, "base"),
    "models": (1, "models"),
    "simulation": (2, "simulation"),
    "analysis": (3, "analysis"),
    "io": (4, "io"),
    "plots": (4, "plots"),
    "reports": (4, "reports"),
    "cli": (5, "cli"),
}
FACADE = (6, "api")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules() -> dict[str, Path]:
    found = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    found["tcsim._core"] = PACKAGE / "_core.pyi"
    return found


def resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    """The absolute name of a relative import ``from <level dots><target> import ...``."""
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    base = base[: len(base) - (level - 1)] if level > 1 else base
    return ".".join(base + ([target] if target else []))


def imports_of(name: str, path: Path, known: set[str]) -> set[str]:
    """The tcsim modules ``name`` imports anywhere in its body (names imported from a package that
    are its submodules count as imports of those submodules)."""
    if path.suffix == ".pyi":
        return set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    is_package = path.name == "__init__.py"
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.split(".")[0] == "tcsim")
        elif isinstance(node, ast.ImportFrom):
            target = resolve(name, is_package, node.level, node.module) if node.level else node.module or ""
            if target.split(".")[0] != "tcsim":
                continue
            out.add(target)
            out.update(f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in known)
    # an import of tcsim.a.b also imports the packages tcsim.a and tcsim; those are not edges here
    return {m for m in out if m in known and m != name and m != "tcsim"}


def graph() -> dict[str, set[str]]:
    mods = modules()
    known = set(mods)
    return {name: imports_of(name, path, known) for name, path in mods.items()}


def layer(module: str) -> tuple[int, str]:
    parts = module.split(".")
    if len(parts) == 1:
        return FACADE
    return LAYERS.get(parts[1], FACADE)


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """One cycle as a list of modules (first repeated at the end), or None."""
    state: dict[str, int] = {}  # 1: on the stack, 2: done
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt) :] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(edges):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def upward_imports(edges: dict[str, set[str]]) -> list[str]:
    bad = []
    for module, targets in sorted(edges.items()):
        rank, group = layer(module)
        for target in sorted(targets):
            t_rank, t_group = layer(target)
            if t_group == group:
                continue
            if t_rank >= rank:
                bad.append(f"{module} (layer {rank} {group}) imports {target} (layer {t_rank} {t_group})")
    return bad


def test_the_graph_sees_the_package():
    edges = graph()
    assert {"tcsim.models.converter", "tcsim.simulation.transient", "tcsim.cli.launch"} <= set(edges)
    assert "tcsim.models.characteristic" in edges["tcsim.models.converter"]
    assert "tcsim._core" in edges["tcsim.models.converter"]  # `from .. import _core`


def test_no_import_cycles():
    assert find_cycle(graph()) is None


def test_imports_go_down_the_layers():
    assert upward_imports(graph()) == []


def test_a_cycle_and_an_upward_import_are_found():
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}
    assert find_cycle(edges) == ["a", "b", "c", "a"]
    assert upward_imports({"tcsim.models.x": {"tcsim.cli.app"}}) != []
    assert upward_imports({"tcsim.io.x": {"tcsim.plots.common"}}) != []  # siblings
    assert upward_imports({"tcsim.cli.x": {"tcsim.io.outputs", "tcsim.errors"}}) == []


@pytest.mark.parametrize(
    ("module", "is_package", "level", "target", "expected"),
    [
        ("tcsim.models.converter", False, 1, "tables", "tcsim.models.tables"),
        ("tcsim.models.converter", False, 2, None, "tcsim"),
        ("tcsim.models.converter", False, 2, "errors", "tcsim.errors"),
        ("tcsim.cli", True, 1, "app", "tcsim.cli.app"),
        ("tcsim", True, 1, "models.dynamic", "tcsim.models.dynamic"),
    ],
)
def test_relative_imports_resolve(module, is_package, level, target, expected):
    assert resolve(module, is_package, level, target) == expected


FACADES = ("transient", "replay", "fmu", "fitting", "shape_fit", "steady", "study", "measurement")


@pytest.mark.parametrize("name", FACADES)
def test_facades_only_re_export(name):
    """A documented path that moved is a thin facade: a docstring, imports and ``__all__``."""
    tree = ast.parse((PACKAGE / f"{name}.py").read_text(encoding="utf-8"))
    for node in tree.body[1:]:
        is_all = isinstance(node, ast.Assign) and [getattr(t, "id", None) for t in node.targets] == ["__all__"]
        assert isinstance(node, ast.ImportFrom) or is_all, (name, ast.dump(node)[:80])
    assert layer(f"tcsim.{name}") == FACADE
