"""MkDocs hooks of the documentation site (``hooks:`` in ``mkdocs.yml``).

MkDocs puts this file's folder on ``sys.path`` while it loads the hook, so the generator
``tools/docs_reference.py`` is imported as ``docs_reference``.
"""

from __future__ import annotations

from typing import Any

from mkdocs.structure.files import File, Files

import docs_reference


def on_files(files: Files, config: Any) -> Files:
    """Add the generated input-file reference (:data:`docs_reference.PAGE`) to the site's files."""
    files.append(File.generated(config, docs_reference.PAGE, content=docs_reference.page()))
    return files
