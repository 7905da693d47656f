"""Griffe extensions for the API reference: the installed import paths and the public surface.

``AgentsAsSubpackage``: ``pyproject.toml`` installs the top-level folder ``agents/`` as
``orbit_env.agents``; griffe reads source folders and would otherwise document it as a
top-level package ``agents``, with ``agents.…`` in every heading, signature and anchor.

``PublicSurface``: a module without ``__all__`` documents its classes and functions, and
of its constants only those the manuals name (in backticks) and those of
``orbit_env.constants``; a table's row indices or a cache's format number are not API.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import griffe

DOCS = Path(__file__).parent
#: Modules whose constants are all public.
CONSTANT_MODULES = ("orbit_env.constants",)


class AgentsAsSubpackage(griffe.Extension):
    """After ``orbit_env`` is loaded, load ``agents/`` and attach it as its member ``agents``."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        """Attach the folder ``agents/`` to the package ``orbit_env`` under the name ``agents``."""
        if pkg.path != "orbit_env" or "agents" in pkg.members:
            return
        agents = loader.load("agents", find_stubs_package=False)
        pkg.set_member("agents", agents)
        loader.modules_collection.del_member("agents")


def named_in_manuals() -> set[str]:
    """Every identifier inside backticks in the manuals (the docs pages but the API pages, README)."""
    pages = [p for p in DOCS.rglob("*.md") if "api" not in p.relative_to(DOCS).parts]
    text = " ".join(p.read_text(encoding="utf-8") for p in [*pages, DOCS.parent / "README.md"])
    return set(re.findall(r"[A-Za-z_]\w*", " ".join(re.findall(r"`([^`]+)`", text))))


class PublicSurface(griffe.Extension):
    """Drop the constants of modules without ``__all__`` that the manuals do not name."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        """Prune the package ``orbit_env`` (agents included) once it is loaded."""
        if pkg.path != "orbit_env":
            return
        named = named_in_manuals()

        def prune(module: griffe.Module) -> None:
            for name, member in list(module.members.items()):
                if member.is_alias:
                    continue
                if member.is_module:
                    prune(member)
                elif (
                    member.is_attribute
                    and module.exports is None
                    and module.path not in CONSTANT_MODULES
                    and name not in named
                ):
                    module.del_member(name)

        prune(pkg)
