"""README.md: no link leaves the repository, every relative link resolves to a file of the checkout,
and every path its Layout section names exists."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
README = (REPO / "README.md").read_text(encoding="utf-8")


def links(text: str) -> list[str]:
    """Targets of Markdown links ``[text](target)``, autolinks ``<scheme:...>`` and bare URLs."""
    inline = re.findall(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", text)
    reference = re.findall(r"^\s*\[[^\]]+\]:\s*(\S+)", text, flags=re.M)
    auto = re.findall(r"<([a-zA-Z][a-zA-Z0-9+.-]*:[^>\s]+)>", text)
    bare = re.findall(r"(?<![(<])\b(?:https?|ftp)://\S+", text)
    return inline + reference + auto + bare


def test_links_extracted():
    found = links("[a](docs/x.md) [b](https://e.org) <http://e.org> see http://x.y [c]: ../y.md\n")
    assert found[:2] == ["docs/x.md", "https://e.org"] and "http://e.org" in found and "http://x.y" in found


def test_no_readme_link_leaves_the_repository():
    targets = links(README)
    assert targets
    for target in targets:
        assert not re.match(r"[a-zA-Z][a-zA-Z0-9+.-]*:|//", target), f"{target}: a link outside the repository"
        path = (REPO / target.split("#")[0]).resolve()
        assert path.is_relative_to(REPO), f"{target}: outside the checkout"
        assert path.exists(), f"{target}: no such file in the repository"


def layout_paths(text: str) -> list[Path]:
    """The paths the Layout block names: a top-level line's first column, and the comma-separated
    names of the lines indented by two below it (inside it, or inside its ``src/``)."""
    block = text.split("## Layout", 1)[1].split("```", 2)[1]
    out: list[Path] = []
    parent = REPO
    for line in block.splitlines():
        m = re.match(r"^( ?( ?))(\S.*?)(?:\s{2,}|$)", line)
        if m is None or len(m[1]) not in (0, 2):
            continue
        names = [n.strip().rstrip("/") for n in m[3].split(",") if n.strip()]
        if not m[1]:
            paths = [REPO / n for n in names if "*" not in n]
            parent = paths[0] if paths else REPO
        else:
            paths = [parent / n if (parent / n).exists() else parent / "src" / n for n in names]
        out += paths
    return out


def test_every_path_the_layout_names_exists():
    paths = layout_paths(README)
    assert len(paths) > 30
    missing = [str(p.relative_to(REPO)) for p in paths if not p.exists()]
    assert not missing, f"README.md Layout names paths that do not exist: {missing}"


def test_the_layout_names_every_part_of_the_package_and_the_core():
    named = set(layout_paths(README))
    parts = [
        *(p for p in (REPO / "python" / "tcsim").iterdir() if p.is_dir() and p.name != "__pycache__"),
        *(p for p in (REPO / "python" / "tcsim").glob("*.py") if p.name not in ("__init__.py", "__main__.py")),
        *(p for p in (REPO / "crates" / "tcsim-core" / "src").iterdir() if p.name != "lib.rs"),
        *(REPO / "crates").iterdir(),
    ]
    unnamed = sorted(str(p.relative_to(REPO)) for p in parts if p not in named)
    assert not unnamed, f"README.md Layout does not name: {unnamed}"
