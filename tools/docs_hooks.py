"""MkDocs hooks of the documentation site (``hooks:`` in ``mkdocs.yml``).

MkDocs puts this file's folder on ``sys.path`` while it loads the hook, so the generator
``tools/docs_reference.py`` is imported as ``docs_reference``.
"""

from __future__ import annotations

import re
from typing import Any

from mkdocs.structure.files import File, Files

import docs_reference

#: A Sphinx cross-reference role as mkdocstrings renders it from a docstring (``:func:`x```).
_ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|exc|obj):<code>(~?)([^<]*)</code>")


def on_files(files: Files, config: Any) -> Files:
    """Add the generated input-file reference (:data:`docs_reference.PAGE`) to the site's files."""
    files.append(File.generated(config, docs_reference.PAGE, content=docs_reference.page()))
    return files


def plain_roles(html: str) -> str:
    """The docstrings' Sphinx roles as plain code: ``:class:<code>~a.b.C</code>`` → ``<code>C</code>``."""
    return _ROLE.sub(lambda m: f"<code>{m[2].rsplit('.', 1)[-1] if m[1] else m[2]}</code>", html)


def on_page_content(html: str, page: Any, config: Any, files: Files) -> str:
    """Render the Sphinx roles of the API reference's docstrings as plain code."""
    return plain_roles(html)
