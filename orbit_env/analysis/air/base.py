"""What the analysis asks of an atmosphere, as one object: the air a decay runs in.

Each model is one class in one module of this package, and `orbit_env.analysis.air`
registers it by name; nothing else in the package switches on a model's name. Adding a
model is one module here plus one line in the registry. An air answers what callers ask:

* its density profile at an inclination (`Air.profile`), or, when it follows a date
  (`Air.dated`), the time-stepped model of `orbit_env.decay.chunked` (`Air.solar_model`);
* whether the profile depends on the inclination (`Air.depends_on_inclination`);
* which heights are natural for it (`Air.height_reference`) and its law in the heights
  above the decay core's 6371 km sphere (`Air.in_sphere_heights`);
* whether its air co-rotates with the Earth unless told otherwise (`Air.corotates`);
* a line that describes it (`Air.describe`) and how it is built from the command line's
  options (`Air.from_options`, `Air.options`).

Units: SI (m, kg/m^3, days since 1970-01-01 for dates).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import UniversalCurves, universal_curves
from orbit_env.decay.solar import ConstantActivity, SolarActivity
from orbit_env.physics.atmosphere import Atmosphere

#: The activity of a gas whose air has no temperature of its own (a shape's C_D): moderate.
MODERATE_ACTIVITY = ConstantActivity(150.0, 150.0, 15.0)


class Air(ABC):
    """One atmosphere model as the analysis uses it (subclasses are frozen dataclasses).

    Class attributes:
        name: The registry's key (``--atmosphere NAME``, a catalogue's ``atmosphere`` column).
        options: The command-line options (argparse ``dest`` names) that belong to this model.
        height_reference: Heights a user gives are above this surface unless told otherwise
            (``sphere``: the paper's 6371 km Earth; ``equatorial``: WGS84's 6378.137 km).
        corotates: The air co-rotates with the Earth unless told otherwise.
        curves_by_default: The command line answers through the universal curves where the
            orbit lies on them (else through the averaged equations).
    """

    name: ClassVar[str]
    options: ClassVar[tuple[str, ...]] = ()
    height_reference: ClassVar[str] = "equatorial"
    corotates: ClassVar[bool] = False
    curves_by_default: ClassVar[bool] = True

    #: The start date [unix days] a dated air follows (None: no date).
    epoch_days: float | None = None
    #: The solar activity the air responds to, as given (None: none given, or the air does not respond).
    activity: SolarActivity | None = None

    @property
    def dated(self) -> bool:
        """True when the air follows a date (the time-stepped path), False for one fixed profile."""
        return self.epoch_days is not None

    @property
    def depends_on_inclination(self) -> bool:
        """True when the profile differs between inclinations."""
        return False

    @abstractmethod
    def profile(self, inclination_deg: float, scale: float = 1.0) -> Atmosphere:
        """The one density profile of an air that does not change in time.

        Raises:
            ValueError: the air is dated (it has no single profile).
        """

    @abstractmethod
    def describe(self, inclination_deg: float, details: str = "") -> str:
        """One line for the command line; ``details`` (the steps, a scale) goes where it reads best."""

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> Air:
        """The air from the command line's options (``options[dest]``, None where not given)."""
        return cls()

    def curves(self, model: DecayModel) -> UniversalCurves:
        """The universal curves of this air's decay model (cached per process and on disk)."""
        return universal_curves(model)

    def density_near_kg_m3(
        self, altitude_m: Any, inclination_deg: float, epoch_days: float | None, span_days: int
    ) -> NDArray[np.float64]:
        """The orbit-averaged density [kg/m^3] at altitudes above the 6371 km sphere, over the days before a date.

        A fixed profile is the same on every date; a dated air averages its days
        ``epoch_days - span_days + 1 .. epoch_days`` (the air an element set was fitted in).
        """
        return np.asarray(self.profile(inclination_deg).density_kg_m3(altitude_m), dtype=np.float64)

    def in_sphere_heights(self, reference: str, inclination_deg: float) -> Air:
        """The same air as a law in heights above the 6371 km sphere, for heights quoted above ``reference``."""
        return self

    def gas_activity(self) -> tuple[SolarActivity, float | None]:
        """The activity and date [unix days] whose gas temperature sets a shape's C_D."""
        return MODERATE_ACTIVITY, None

    def mean_density_over_inclinations_kg_m3(self, altitude_m: Any, inclinations_deg: Any, **nodes: Any) -> Any:
        """The year-averaged density at several inclinations, rows per inclination (None: independent of it)."""
        return None

    def solar_model(self, inclination_deg: float, **settings: Any) -> Any:
        """The time-stepped decay model of a dated air (`orbit_env.decay.chunked.SolarDecayModel`).

        Raises:
            ValueError: the air has one fixed profile.
        """
        raise ValueError(f"the {self.name} atmosphere does not change in time; it has one profile")
