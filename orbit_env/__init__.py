"""orbit_env: satellite decay by Okhotsimsky, Eneev and Taratynova (1957).

A fast orbit-averaged decay simulator built on the paper's universal curves, and
Gymnasium environments in which an agent decides when a perigee burn pays off.
"""

from __future__ import annotations

import importlib.abc
import importlib.util
import sys
from collections.abc import Sequence
from importlib.machinery import ModuleSpec
from types import ModuleType

from orbit_env.analysis.lifetime import LifetimeResult, Satellite, lifetime
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import universal_curves
from orbit_env.envs import register_envs
from orbit_env.physics.atmosphere import ExponentialAtmosphere, PaperAtmosphere


class _RegisterWhenImported(importlib.abc.MetaPathFinder):
    """Registers the environments as soon as Gymnasium has been imported, by whatever imports it.

    `import orbit_env` then `gymnasium.make("OrbitRaising-v0")` works in either order of the
    imports, while a command that decays an orbit does not import Gymnasium at all (30 ms of a
    command's 0.25 s). The finder steps aside at once: Gymnasium is found and loaded as
    always, its loader running the registration after the module's own code.
    """

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != "gymnasium":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is not None and isinstance(spec.loader, importlib.abc.Loader):
            run = spec.loader.exec_module

            def exec_module(module: ModuleType) -> None:
                run(module)
                register_envs()

            spec.loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


if "gymnasium" in sys.modules:
    register_envs()
elif not any(isinstance(finder, _RegisterWhenImported) for finder in sys.meta_path):
    sys.meta_path.insert(0, _RegisterWhenImported())

__all__ = [
    "DecayModel",
    "ExponentialAtmosphere",
    "LifetimeResult",
    "PaperAtmosphere",
    "Satellite",
    "lifetime",
    "universal_curves",
]
__version__ = "0.1.0"
