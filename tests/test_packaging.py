"""The installed package is the source tree: every folder with an ``__init__.py`` is in pyproject's packages.

pyproject lists the packages by hand (agents/ installs as orbit_env.agents); a folder added without its line
installs nothing of it. orbit_env.analysis.air had been left out: every wheel built failed at ``import orbit_env``,
while the editable install the README and CI use read the folder itself (found by the packaging review of
2026-12-06, which installed the wheel).
"""

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_every_package_folder_is_installed():
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setuptools["packages"])
    folders = setuptools["package-dir"]  # package -> folder
    found = set()
    for package, folder in folders.items():
        for init in (ROOT / folder).rglob("__init__.py"):
            parts = init.parent.relative_to(ROOT / folder).parts
            found.add(".".join((package, *parts)))
    assert found - listed == set(), "folders with an __init__.py that pyproject does not install"
    assert listed - found == set(), "packages pyproject installs that have no folder"
