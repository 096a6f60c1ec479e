"""Griffe extension: the package's Sphinx roles rendered as code on the API pages.

The docstrings cross-reference with Sphinx roles (``:func:`load_config```,
``:class:`~cartpole_q.config.Config```), which mkdocstrings would print as they are. This
turns each into inline code, the target's last component when it starts with ``~`` (as
Sphinx shows it), without touching the package.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(
    r":(?:func|class|mod|meth|attr|data|exc|obj|const):`(?P<tilde>~?)(?P<target>[^`]+)`"
)
"""a Sphinx cross-reference role and its target"""


def plain(text: str) -> str:
    """The text with every role replaced by its target as inline code.

    >>> plain("see :func:`load_config` and :class:`~cartpole_q.config.Config`")
    'see `load_config` and `Config`'
    """

    def code(match: re.Match[str]) -> str:
        target = match["target"]
        return f"`{target.rsplit('.', 1)[-1] if match['tilde'] else target}`"

    return ROLE.sub(code, text)


class SphinxRoles(griffe.Extension):
    """Rewrite the roles of every docstring griffe loads."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        """Each object (module, class, function, attribute) as griffe creates it."""
        if obj.docstring is not None:
            obj.docstring.value = plain(obj.docstring.value)
