"""The air a decay runs in: one class per atmosphere model, and the registry of their names.

Adding a model is one module in this package (a frozen dataclass subclassing `Air`) and one
line in `AIR_MODELS`; the command line's ``--atmosphere`` choices, a catalogue's models and
every question the analysis asks of an atmosphere go through the class (see `Air`).
"""

from orbit_env.analysis.air.base import Air
from orbit_env.analysis.air.exponential import ExponentialAir
from orbit_env.analysis.air.msis import MsisAir
from orbit_env.analysis.air.paper import PaperAir
from orbit_env.analysis.air.profile import ProfileAir

#: The models a user names (``--atmosphere NAME``), by name.
AIR_MODELS: dict[str, type[Air]] = {cls.name: cls for cls in (PaperAir, ExponentialAir, MsisAir)}
#: The model when none is named: the paper's.
DEFAULT_AIR = PaperAir.name
#: The model a date selects when none is named (an element set's epoch, ``--epoch``): NRLMSIS under the real Sun.
DATED_AIR = MsisAir.name


def air_model(name: str) -> type[Air]:
    """The class of the model called ``name``.

    Raises:
        ValueError: no model has that name (the message lists the names).
    """
    try:
        return AIR_MODELS[name]
    except KeyError:
        raise ValueError(f"atmosphere must be one of {', '.join(AIR_MODELS)}, got {name!r}") from None


__all__ = [
    "AIR_MODELS",
    "DATED_AIR",
    "DEFAULT_AIR",
    "Air",
    "ExponentialAir",
    "MsisAir",
    "PaperAir",
    "ProfileAir",
    "air_model",
]
