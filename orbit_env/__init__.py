"""orbit_env: satellite decay by Okhotsimsky, Eneev and Taratynova (1957).

A fast orbit-averaged decay simulator built on the paper's universal curves, and
Gymnasium environments in which an agent decides when a perigee burn pays off.
"""

from orbit_env.analysis.lifetime import LifetimeResult, Satellite, lifetime
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import universal_curves
from orbit_env.envs import register_envs
from orbit_env.physics.atmosphere import ExponentialAtmosphere, PaperAtmosphere

# `import orbit_env` then `gymnasium.make("OrbitRaising-v0")`: the ids live in one place.
register_envs()

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
