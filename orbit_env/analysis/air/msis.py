"""NRLMSIS (2.1, 2.0 or NRLMSISE-00) under constant, tabulated, cyclic or the real Sun's activity; dated by an epoch."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from orbit_env.analysis.air.base import Air
from orbit_env.checks import check_date
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import UniversalCurves
from orbit_env.decay.solar import (
    DEFAULT_AP,
    ConstantActivity,
    CycleActivity,
    SolarActivity,
    TableActivity,
    iso_date,
    read_solar_csv,
    unix_days,
)
from orbit_env.physics.atmosphere.msis import (
    DEFAULT_MSIS_VERSION,
    MSIS_VERSION_NAMES,
    MsisAtmosphere,
    check_msis_version,
)

#: NRLMSIS's activity when none is given: F10.7 = 150 sfu (daily and 81-day mean), Ap = 15.
DEFAULT_ACTIVITY = ConstantActivity(150.0, 150.0, 15.0)
#: The versions as the command line writes them (``--msis-version``), and the version each is.
MSIS_VERSION_CHOICES = {"2.1": 2.1, "2.0": 2.0, "00": 0.0}


@dataclass(frozen=True)
class MsisAir(Air):
    """NRLMSIS, orbit-averaged (`orbit_env.physics.atmosphere.msis`).

    Args:
        activity: Indices against time (default: F10.7 = 150, Ap = 15, constant).
        epoch_days: Unix days of the orbit's epoch. It switches on the time-stepped path,
            which follows the season and any change in activity.
        ascending_node_local_time_h: Sun-synchronous orbits: the node's local solar time.
        follow_season: The time-stepped path follows the season from the epoch (False: the
            season averaged, for an activity placed on a date that is not the orbit's).
        version: NRLMSIS version: 2.1 (default), 2.0, or 0.0 for NRLMSISE-00 (to compare
            with tools that run it: STK, Orekit).
        storm_ap: The time-stepped path takes NRLMSIS's storm-time mode (3-hourly ap history) on
            the storm days of an activity that has the 3-hourly ap (the CelesTrak record);
            False (``--daily-ap``): the daily Ap every day
            (`orbit_env.decay.chunked.SolarDecayModel`).
    """

    name: ClassVar[str] = "msis"
    # The real air turns with the Earth (a life at 0 deg about 14% longer than in still air); --still-air compares.
    corotates: ClassVar[bool] = True
    options: ClassVar[tuple[str, ...]] = (
        "f107",
        "f107a",
        "ap",
        "solar_csv",
        "solar_cycle",
        "cycle_phase",
        "epoch",
        "node_local_time",
        "msis_version",
        "daily_ap",
    )

    activity: SolarActivity | None = None
    epoch_days: float | None = None
    ascending_node_local_time_h: float | None = None
    follow_season: bool = True
    version: float = DEFAULT_MSIS_VERSION
    storm_ap: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "version", check_msis_version(self.version))
        if self.epoch_days is not None:
            if isinstance(self.epoch_days, str):
                text = self.epoch_days
                raise TypeError(f"epoch_days={text!r} must be unix days (orbit_env.decay.solar.unix_days({text!r}))")
            first = getattr(self.activity, "start_days", None)  # a table may start before Sputnik (the record: 3 days)
            if first is None or self.epoch_days != first:
                object.__setattr__(self, "epoch_days", check_date(self.epoch_days, "epoch_days"))
        if self.epoch_days is None and self.activity is not None and not isinstance(self.activity, ConstantActivity):
            raise ValueError("activity that changes with time needs an epoch (a start date)")

    @property
    def depends_on_inclination(self) -> bool:
        """NRLMSIS is averaged over the latitudes the orbit flies over."""
        return True

    @property
    def solar(self) -> SolarActivity:
        """The activity (default: constant F10.7 = 150 sfu, Ap = 15)."""
        return self.activity if self.activity is not None else DEFAULT_ACTIVITY

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> MsisAir:
        """``--epoch``, ``--solar-csv``, ``--solar-cycle``/``--cycle-phase``, ``--f107/--f107a/--ap``, the version.

        A date and no other solar option: the real Sun (the shipped or imported record).
        ``msis_version`` is a key of `MSIS_VERSION_CHOICES` (None: 2.1).
        """
        text = options.get("epoch")
        epoch = None if text is None else check_date(unix_days(text), "--epoch", text=text)
        f107, f107a, ap = options.get("f107"), options.get("f107a"), options.get("ap")
        solar_csv, solar_cycle, phase = options.get("solar_csv"), options.get("solar_cycle"), options.get("cycle_phase")
        activity: SolarActivity
        if solar_csv and solar_cycle:
            raise ValueError("give either --solar-csv or --solar-cycle, not both")
        if (solar_csv or solar_cycle) and (f107 is not None or f107a is not None):
            raise ValueError("--f107/--f107a set constant activity; they do not combine with --solar-csv/--solar-cycle")
        if phase is not None and not solar_cycle:
            raise ValueError("--cycle-phase applies to --solar-cycle")
        if solar_csv:
            activity = read_solar_csv(solar_csv, default_ap=DEFAULT_AP if ap is None else ap)
            if epoch is None:
                epoch = activity.start_days
        elif solar_cycle:
            if epoch is None:
                raise ValueError("--solar-cycle needs --epoch (the orbit's date; it sets the phase and the season)")
            activity = CycleActivity() if phase is None else CycleActivity.with_phase(phase, epoch)
        elif epoch is not None and f107 is None and f107a is None and ap is None:
            from orbit_env.decay.solar_record import load_record

            activity = load_record()
        else:
            f107 = DEFAULT_ACTIVITY.f107_sfu if f107 is None else f107
            ap = DEFAULT_ACTIVITY.ap if ap is None else ap
            activity = ConstantActivity(f107, f107 if f107a is None else f107a, ap)
        text_version = options.get("msis_version")
        if text_version is not None and text_version not in MSIS_VERSION_CHOICES:
            raise ValueError(f"--msis-version must be one of {', '.join(MSIS_VERSION_CHOICES)}, got {text_version!r}")
        version = DEFAULT_MSIS_VERSION if text_version is None else MSIS_VERSION_CHOICES[text_version]
        storm_ap = not options.get("daily_ap")
        return cls(activity, epoch, options.get("node_local_time"), version=version, storm_ap=storm_ap)

    def profile(self, inclination_deg: float, scale: float = 1.0) -> MsisAtmosphere:
        """The profile of constant activity, averaged over the year (an air without a date)."""
        if self.dated:
            raise ValueError("this scenario changes in time; it has no single profile")
        solar = self.solar
        assert isinstance(solar, ConstantActivity)
        return MsisAtmosphere(
            solar.f107_sfu,
            solar.f107a_sfu,
            solar.ap,
            inclination_deg,
            None,
            self.ascending_node_local_time_h,
            scale,
            self.version,
        )

    def curves(self, model: DecayModel) -> UniversalCurves:
        """The larger cache: batches may hold many inclinations."""
        from orbit_env.decay.chunked import cached_curves

        return cached_curves(model)

    def solar_model(self, inclination_deg: float, **settings: Any) -> Any:
        """The time-stepped model from the epoch (``settings``: rotating_atmosphere, chunk_days, max_years)."""
        if self.epoch_days is None:
            return super().solar_model(inclination_deg)
        from orbit_env.decay.chunked import SolarDecayModel

        return SolarDecayModel(
            self.solar,
            self.epoch_days,
            inclination_deg,
            follow_season=self.follow_season,
            ascending_node_local_time_h=self.ascending_node_local_time_h,
            version=self.version,
            storm_ap=self.storm_ap,
            **settings,
        )

    def gas_activity(self) -> tuple[SolarActivity, float | None]:
        """Its own activity, on its epoch."""
        return self.solar, self.epoch_days

    def density_near_kg_m3(
        self, altitude_m: Any, inclination_deg: float, epoch_days: float | None, span_days: int
    ) -> Any:
        """Dated: the mean of each day's orbit-averaged density over the span, with the days' indices (and season)."""
        if not self.dated or epoch_days is None:
            return super().density_near_kg_m3(altitude_m, inclination_deg, epoch_days, span_days)
        from orbit_env.physics.atmosphere.msis import mean_density_over_days_kg_m3

        f107, f107a, ap, day_of_year = self._days_read(float(epoch_days), span_days)
        return mean_density_over_days_kg_m3(
            altitude_m,
            f107,
            f107a,
            ap,
            day_of_year,
            inclination_deg,
            self.ascending_node_local_time_h,
            version=self.version,
        )

    def _days_read(self, epochs_days: Any, span_days: int) -> Any:
        """F10.7, its 81-day mean, Ap and the day of the year of the ``span_days`` days up to each epoch.

        What `density_near_kg_m3` hands NRLMSIS. Shape (4, *epochs' shape, span_days).
        """
        import numpy as np

        from orbit_env.decay.solar import day_of_year

        days = np.asarray(epochs_days, dtype=np.float64)[..., None] - np.arange(span_days)[::-1]
        return np.stack([*self.solar.indices(days), day_of_year(days)])

    def mean_density_over_inclinations_kg_m3(self, altitude_m: Any, inclinations_deg: Any, **nodes: Any) -> Any:
        """`orbit_env.physics.atmosphere.msis.mean_density_over_inclinations_kg_m3` of constant activity."""
        from orbit_env.physics.atmosphere.msis import mean_density_over_inclinations_kg_m3

        solar = self.solar
        assert isinstance(solar, ConstantActivity)
        return mean_density_over_inclinations_kg_m3(
            altitude_m,
            solar.f107_sfu,
            solar.f107a_sfu,
            solar.ap,
            inclinations_deg,
            self.ascending_node_local_time_h,
            **nodes,
            version=self.version,
        )

    def describe(self, inclination_deg: float, details: str = "") -> str:
        """The model, the activity's source, the inclination (and node), then ``details``."""
        solar = self.solar
        if isinstance(solar, ConstantActivity):
            what = f"F10.7 {solar.f107_sfu:g}, 81-day mean {solar.f107a_sfu:g} sfu, Ap {solar.ap:g}"
        elif hasattr(solar, "describe"):
            what = solar.describe()  # the space-weather record names its source and its eras
        elif isinstance(solar, TableActivity):
            what = f"solar table {solar.source} ({iso_date(solar.start_days)} to {iso_date(solar.end_days)})"
        elif isinstance(solar, CycleActivity):
            what = (
                f"smooth solar cycle, F10.7 {solar.f107_min_sfu:g}-{solar.f107_max_sfu:g} sfu, "
                f"minimum {iso_date(solar.minimum_days)}"
            )
        else:
            what = type(solar).__name__
        where = f"inclination {inclination_deg:g} deg"
        if self.ascending_node_local_time_h is not None:
            where += f", node at {self.ascending_node_local_time_h:g} h local time"
        if not self.storm_ap:
            what += ", daily Ap only (--daily-ap)"
        return f"{MSIS_VERSION_NAMES[self.version]}, {what}, {where}{details}"
