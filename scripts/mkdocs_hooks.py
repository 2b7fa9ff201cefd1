"""MkDocs hook: the docstrings' Sphinx roles read as plain code in the API reference.

Docstrings write ``:class:`Fluent``` and ``:meth:`~pycram.fluent.Fluent.wait_for```; the Python
handler renders them as Markdown, leaving the role name in front of the code. This hook drops
the role and, as Sphinx does for ``~``, shows only the last part of a dotted name. A paragraph
ending in reStructuredText's ``::`` (which introduces a code block) ends in one colon.
"""

from __future__ import annotations

import re
from typing import Any

_LITERAL_MARK = re.compile(r"::(</p>)")
_ROLE = re.compile(r":(?:py:)?(?:class|func|meth|mod|attr|data|exc|obj|const):(<code>)(~?)([^<]*)(</code>)")


def _plain(match: re.Match[str]) -> str:
    opening, tilde, name, closing = match.groups()
    return f"{opening}{name.rsplit('.', 1)[-1] if tilde else name}{closing}"


def on_page_content(html: str, **kwargs: Any) -> str:
    """Rewrite every rendered Sphinx role of the page (called by MkDocs for each page)."""
    return _LITERAL_MARK.sub(r":\1", _ROLE.sub(_plain, html))
