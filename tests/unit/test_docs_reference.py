"""The documentation site's sources (issue 17): the input-file reference generated from the schemas
(``tools/docs_reference.py``) lists every field, every docs page is in the site's nav, and no
message cites a file the user does not have.

These need neither MkDocs nor a build; ``tests/integration/test_docs_site.py`` builds the site."""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

import pytest
from pydantic import BaseModel

from tcsim.io.measurement import INPUT_CHANNELS
from tcsim.models.converter import ConverterFile
from tcsim.models.design_file import DesignFileModel
from tcsim.models.study_file import MonteCarloFile
from tcsim.models.vehicle import bundled_vehicle_names, load_vehicle

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))
import docs_reference  # noqa: E402  (tools/ is not a package)


@pytest.fixture(scope="module")
def page() -> str:
    return docs_reference.page()


def _fields(model: type[BaseModel]) -> list[tuple[str, str]]:
    """(section, key) of every field of ``model`` and of its section models, recursively."""
    out = []
    for key in model.model_fields:
        out.append(("", key))
        section = docs_reference._section_model(model, key)
        if section is not None:
            out += [(key, k) for _, k in _fields(section)]
    return out


def _part(page: str, title: str) -> str:
    """The part of the page under ``## title`` (up to the next ``## ``)."""
    return page.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]


@pytest.mark.parametrize(("model", "title"), [(ConverterFile, "Converter file"), (DesignFileModel, "Design file")])
def test_every_schema_field_is_listed_in_its_section(page, model, title):
    part = _part(page, title)
    fields = _fields(model)
    assert len(fields) > 10
    for section, key in fields:
        where = part.split(f"### `[{section}]`", 1)[1].split("\n### ", 1)[0] if section else part
        assert re.search(rf"^\| `{key}` \|", where, flags=re.M), f"[{section}] {key}: not in the generated table"


def test_every_monte_carlo_file_field_and_distribution_kind_is_listed(page):
    part = _part(page, "Study files").split("### Monte Carlo study", 1)[1]
    for key in MonteCarloFile.model_fields:
        assert re.search(rf"^\| `{key}` \|", part, flags=re.M), key
    for kind in ("normal", "uniform", "lognormal", "truncated-normal", "grid"):
        assert re.search(rf"^\| `{kind}` \| `", part, flags=re.M), kind
    assert "**Grids.** The grid parameters form a full factorial" in part
    assert re.search(r"^\| `runs` \|  \| required with a drawn parameter \| ≥ 1 and ≤ 1e\+07 \|", part, flags=re.M)


def test_the_bounds_and_defaults_are_the_schemas(page):
    converter = _part(page, "Converter file")
    assert re.search(r"^\| `pump_exit_angle_deg` \| ° \| required \| > -90 and < 90", converter, flags=re.M)
    assert re.search(r"^\| `pump_kg_m2` \| kg·m² \| required \| > 0; plausible", converter, flags=re.M)
    assert re.search(r"^\| `lag_time_constant_s` \| s \| optional \| > 0 \|", converter, flags=re.M)
    design = _part(page, "Design file")
    assert re.search(r"^\| `profile` \|  \| optional, default `'circular'` \|", design, flags=re.M)


def test_every_key_of_every_bundled_vehicle_is_listed(page):
    part = _part(page, "Vehicle file")
    tables = {chunk.split("`", 1)[0]: chunk for chunk in part.split("\n### `[")[1:]}  # one table per section
    for name in bundled_vehicle_names():
        vehicle = load_vehicle(name)
        for section, values in vehicle.sections.items():
            for key in values:
                assert f"\n| `{key}` |" in tables[f"{section}]"], f"{name}: [{section}] {key} not listed"


def test_every_measurement_channel_is_listed(page):
    part = _part(page, "Measurement channels")
    for name in INPUT_CHANNELS:
        assert f"| `{name}` |" in part


def test_the_starting_files_are_included(page):
    for kind in ("converter", "vehicle", "design", "scenario", "study"):
        assert f"`tcsim init {kind} --out my_{kind}" in page


def test_comment_and_attribute_notes():
    class A:
        #: the first
        #: line
        a: int
        b: int  # not a note

        #: c's note
        c: int

    assert docs_reference.comment_notes(A) == {"a": "the first line", "c": "c's note"}

    class B:
        """X.

        Attributes
        ----------
        x_m, y_m : float
            Lengths, m.
        p_angle_deg, ..., q_angle_deg : float
            Angles.
        """

    notes = docs_reference.attribute_notes(B)
    assert notes["x_m"] == notes["y_m"] == "Lengths, m."
    assert docs_reference._meaning("r_angle_deg", notes) == "Angles."
    assert docs_reference._meaning("z", notes) == ""


# --------------------------------------------------------------------------------------------
# the site's nav


def nav_pages() -> list[str]:
    """The Markdown files ``mkdocs.yml``'s nav names (``Title: path.md`` lines)."""
    text = (REPO / "mkdocs.yml").read_text(encoding="utf-8")
    nav = text.split("\nnav:\n", 1)[1]
    return re.findall(r"^\s+- [^:\n]+: (\S+\.md)\s*$", nav, flags=re.M)


def test_every_docs_page_is_in_the_nav():
    pages = set(nav_pages())
    stored = {p.relative_to(REPO / "docs").as_posix() for p in (REPO / "docs").rglob("*.md")}
    assert {"index.md", "physics.md", "api/tcsim.md"} <= stored
    assert stored - pages == set(), "docs pages missing from mkdocs.yml's nav (orphans)"
    generated = {docs_reference.PAGE}
    assert pages - stored == generated, "nav entries with no page"


# --------------------------------------------------------------------------------------------
# messages cite files the user has


def _strings(path: Path) -> list[tuple[int, str]]:
    """The string constants of a module that are not docstrings, with their line numbers."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings
    ]


def test_no_message_cites_the_physics_notes_by_a_name_users_do_not_have():
    """Messages and reports cite ``docs/physics.md`` (in the repository and on the site), not
    "physics notes" (issue 17)."""
    found = [
        f"{path.relative_to(REPO)}:{line}"
        for path in sorted((REPO / "python" / "tcsim").rglob("*.py"))
        for line, text in _strings(path)
        if "physics notes" in text
    ]
    assert found == []
    physics = (REPO / "docs" / "physics.md").read_text(encoding="utf-8")
    assert re.search(r"^## 4\. ", physics, flags=re.M) and re.search(r"^## 5\. ", physics, flags=re.M)
