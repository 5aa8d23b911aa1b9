"""List functions longer than a limit in the Rust crates and the Python package.

Rust functions are found on rustfmt-formatted source: a line that opens an ``fn`` item and the
first later line that closes a brace at the same indentation. Python functions come from the
``ast`` (decorators excluded, docstring included). Lengths count every line from the signature
to the closing line, blank lines and comments too.

Usage: ``python tools/function_lengths.py [--limit 80] [ROOT]``; exit 1 when any function is
longer than the limit, with one line per function (``path:line name length``).
"""

from __future__ import annotations

import argparse
import ast
import re
import sys
from collections.abc import Iterator
from pathlib import Path

RUST_FN = re.compile(
    r"^(\s*)(?:pub(?:\([a-z:]+\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?"
    r"(?:extern\s+\"C\"\s+)?fn\s+([A-Za-z_][A-Za-z0-9_]*)"
)


def rust_functions(path: Path) -> Iterator[tuple[str, int, int]]:
    """Yield (name, first line, length) of each ``fn`` with a body in a Rust file."""
    lines = path.read_text(encoding="utf-8").splitlines()
    for i, line in enumerate(lines):
        m = RUST_FN.match(line)
        if m is None:
            continue
        indent = m.group(1)
        # a declaration without a body ends with ';' before any '{' at the item's level
        for j in range(i, len(lines)):
            text = lines[j]
            if text.rstrip().endswith(";") and "{" not in text:
                if j == i or lines[j].startswith(indent) and not lines[j].startswith(indent + " "):
                    break
            if text.rstrip().endswith("{") or text.rstrip().endswith("{}"):
                break
        else:
            continue
        if lines[j].rstrip().endswith("{}") or lines[j].rstrip().endswith(";"):
            continue
        close = re.compile("^" + re.escape(indent) + r"\}")
        for k in range(j + 1, len(lines)):
            if close.match(lines[k]):
                yield m.group(2), i + 1, k - i + 1
                break


def python_functions(path: Path) -> Iterator[tuple[str, int, int]]:
    """Yield (qualified name, first line, length) of each function in a Python file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))

    def walk(node: ast.AST, prefix: str) -> Iterator[tuple[str, int, int]]:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                name = prefix + child.name
                yield name, child.lineno, (child.end_lineno or child.lineno) - child.lineno + 1
                yield from walk(child, name + ".")
            elif isinstance(child, ast.ClassDef):
                yield from walk(child, prefix + child.name + ".")

    yield from walk(tree, "")


def long_functions(root: Path, limit: int) -> list[str]:
    """``path:line name length`` for every function over ``limit`` lines under ``root``."""
    found = []
    for path in sorted((root / "crates").rglob("*.rs")):
        if "target" in path.parts:
            continue
        for name, line, length in rust_functions(path):
            if length > limit:
                found.append(f"{path.relative_to(root)}:{line} {name} {length}")
    for path in sorted((root / "python").rglob("*.py")):
        for name, line, length in python_functions(path):
            if length > limit:
                found.append(f"{path.relative_to(root)}:{line} {name} {length}")
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--limit", type=int, default=80)
    args = parser.parse_args()
    found = long_functions(args.root, args.limit)
    for row in found:
        print(row)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
