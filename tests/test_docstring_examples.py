"""The docstrings' examples run, and are written where the API reference renders them as code.

griffe (the documentation's docstring parser) reads a Google-style ``Examples:`` section as
examples; an ``Example:`` section or a bare ``>>>`` paragraph renders as nested quote blocks.
The env modules' examples run in tests/envs/test_envs.py (they need stable-baselines3).
"""

import doctest
import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import orbit_env

DOCTEST_MODULES = ("orbit_env.checks", "orbit_env.analysis.lifetime", "orbit_env.physics.atmosphere.msis")
ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("name", DOCTEST_MODULES)
def test_examples_run(name):
    result = doctest.testmod(importlib.import_module(name))
    assert result.attempted > 0 and result.failed == 0, name


def test_every_doctest_sits_in_an_examples_section():
    sources = sorted((ROOT / "orbit_env").rglob("*.py")) + sorted((ROOT / "agents").rglob("*.py"))
    offenders = []
    for path in sources:
        lines = path.read_text(encoding="utf-8").splitlines()
        section = None
        for number, line in enumerate(lines, 1):
            stripped = line.strip()
            if re.fullmatch(r"[A-Z][A-Za-z ]*:", stripped) and not stripped.startswith(">>>"):
                section = (len(line) - len(line.lstrip()), stripped)
            if stripped.startswith(">>>"):
                indent = len(line) - len(line.lstrip())
                if section is None or section[1] != "Examples:" or indent <= section[0]:
                    offenders.append(f"{path.relative_to(ROOT)}:{number}")
    assert not offenders, "'>>>' outside an 'Examples:' section: " + ", ".join(offenders)


def test_package_walk_finds_the_modules():
    names = {m.name for m in pkgutil.walk_packages(orbit_env.__path__, "orbit_env.")}
    assert set(DOCTEST_MODULES) <= names
