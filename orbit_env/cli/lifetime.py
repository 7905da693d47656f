"""``orbit-env lifetime`` (one orbit or a CSV catalogue) and ``orbit-env fit-density``: the analyst's commands.

Heights are in km here and converted to SI at once; the batch CSV format is in
`orbit_env.analysis.catalogue`, the solar CSV format in `orbit_env.decay.solar`,
the observations of ``fit-density`` in `orbit_env.analysis.density_fit`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from typing import Any

import numpy as np

from orbit_env.analysis.air import AIR_MODELS, DATED_AIR, DEFAULT_AIR, air_model
from orbit_env.analysis.air.msis import DEFAULT_ACTIVITY, MSIS_VERSION_CHOICES
from orbit_env.analysis.density_fit import HEIGHT_SIGMA_KM, REENTRY_SIGMA_DAYS
from orbit_env.analysis.drag_source import SOURCE_DEFAULT, SOURCE_SATELLITE, DragSource, drag_sigma
from orbit_env.analysis.lifetime import (
    METHODS,
    PAPER_DRAG_COEFFICIENT,
    Satellite,
    check_rule,
    lifetime,
    make_satellite,
)
from orbit_env.analysis.scenario import Scenario
from orbit_env.checks import check_number
from orbit_env.cli import orbit_inputs, uncertain_batch
from orbit_env.cli.common import (
    PROG,
    check_figure,
    check_finite,
    check_output,
    flag,
    given,
    in_files,
    number,
    output_file,
    positive_int,
    write_csv,
)
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.chunked import DEFAULT_CHUNK_DAYS
from orbit_env.decay.solar import (
    DEFAULT_AP,
    SolarTableWarning,
    TableActivity,
    iso_date,
    unix_days,
)


def _scenario(args: argparse.Namespace) -> Scenario:
    """The air and its stepping as chosen on the command line (each model reads its own options)."""
    chosen = air_model(args.atmosphere)
    for model in AIR_MODELS.values():
        for name in model.options:
            if model is not chosen and name not in chosen.options and given(args, name):
                raise ValueError(f"{flag(name)} applies to --atmosphere {model.name}")
    air = chosen.from_options({name: getattr(args, name) for name in chosen.options})
    if args.rotating_atmosphere and args.still_air:
        raise ValueError("give either --rotating-atmosphere or --still-air, not both")
    # None: the model's own default (NRLMSIS co-rotates, the paper's and the exponential law are still).
    rotating = True if args.rotating_atmosphere else (False if args.still_air else None)
    chunk_days = DEFAULT_CHUNK_DAYS if args.chunk_days is None else args.chunk_days
    scenario = Scenario(air, args.density_scale, rotating, chunk_days)
    if args.chunk_days is not None and scenario.epoch_days is None:
        raise ValueError("--chunk-days is the time step of a dated decay: it goes with --epoch (or an element set's)")
    if getattr(args, "daily_ap", False) and scenario.epoch_days is None:
        raise ValueError("--daily-ap chooses a dated decay's Ap: it goes with --epoch (or an element set's)")
    table, epoch = scenario.activity, scenario.epoch_days
    if isinstance(table, TableActivity) and epoch is not None and epoch > table.end_days + 1.0:
        raise ValueError(
            f"the solar table {table.source} ends on {iso_date(table.end_days)}, before the decay starts on "
            f"{iso_date(epoch)}: none of its days is one of the decay's; give a table that covers them, or no "
            "--solar-csv (the shipped record and its forecast)"
        )
    return scenario


def _satellite(args: argparse.Namespace) -> Satellite:
    cx = PAPER_DRAG_COEFFICIENT if args.cx is None else args.cx
    return make_satellite(cx, args.mass, args.area, args.mass_per_area)


def _atmosphere(args: argparse.Namespace, scenario: Scenario, *, batch: bool = False, result: Any = None) -> str:
    """The atmosphere line; says so when the inclination it depends on is the default, not the user's.

    With ``batch``, the inclination is each row's (its ``inclination_deg``), ``--inclination`` only
    where a row gives none: the line says so, where the scenario's one inclination would mislead;
    so does the date of a batch of element sets, each row's air from its own epoch.
    """
    text = scenario.describe(args.inclination)
    if result is not None and result.method == "averaged" and scenario.epoch_days is not None:
        # Above the curves' domain a dated decay is not stepped: one mean air over the life (lifetime_mean).
        steps = f" in {scenario.chunk_days:g}-day steps"
        text = text.replace(steps, ", averaged over the lifetime (the orbit lies above the universal curves)")
    if batch and getattr(args, "rows_own_epochs", False) and scenario.epoch_days is not None:
        own = "from each row's epoch (its latest element set) in"
        text = text.replace(f"from {iso_date(scenario.epoch_days)} in", own)
    defaulted = scenario.depends_on_inclination and getattr(args, "inclination_defaulted", False)
    if batch and scenario.depends_on_inclination:
        default = "the default, no --inclination given" if defaulted else "--inclination"
        rows = f"each row's inclination_deg ({args.inclination:g} deg where a row has none: {default})"
        if getattr(args, "batch_element_sets", False):
            rows = "each row's inclination (its element set's)"
        return text.replace(f"inclination {args.inclination:g} deg", rows)
    if defaulted:
        text += " (the default: no --inclination given)"
    return text


def _warn_solar_table(scenario: Scenario, last_day: float) -> None:
    """Warn on stderr when a solar table does not cover the decay, from the epoch to ``last_day`` [unix days].

    Outside its rows a table's first or last row is held (`TableActivity`); the warning gives
    the dates and says that this is what was done. Hook: once a shipped record and forecast can
    extend a table, extend it in `_scenario` and say so here instead.
    """
    solar = scenario.activity
    if not isinstance(solar, TableActivity) or scenario.epoch_days is None:
        return
    text = solar.held_outside(scenario.epoch_days, last_day)
    if text is not None:
        print(f"{PROG}: warning: {text}", file=sys.stderr)


def _check_inclination(args: argparse.Namespace) -> None:
    """Check --inclination before anything uses it (a batch's rows and the height conversions do)."""
    if args.inclination is not None:
        check_number(args.inclination, "inclination_deg", unit="deg", low=0.0, high=180.0)


def _days_text(days: float) -> str:
    """A lifetime in days and years; under a day in three digits and hours, never "0.00 days"."""
    if days >= 1.0 or days == 0.0:
        return f"{days:.2f} days ({days / DAYS_PER_YEAR:.2f} years)"
    return f"{days:.3g} days ({days * 24.0:.3g} hours)"


def _json(summary: dict[str, Any]) -> str:
    """One JSON object; NaN and infinities are refused here rather than printed (they are not JSON)."""
    check_finite(summary, "the result")
    return json.dumps(summary, allow_nan=False)


def _check_on_the_curves(perigee_km: float, apogee_km: float, offset_km: float) -> None:
    """Refuse ``--uncertainty`` for an orbit off the universal curves, in the heights typed, before any decay.

    Its samples decay on the curves (`orbit_env.analysis.uncertainty`); a thousand decays by the averaged
    equations (a geostationary transfer orbit's) would take hours.
    """
    from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M

    top, apogee_top = (h / 1e3 - offset_km for h in (CURVES_MAX_PERIGEE_M, CURVES_MAX_APOGEE_M))
    if perigee_km > CURVES_MAX_PERIGEE_M / 1e3 or apogee_km > CURVES_MAX_APOGEE_M / 1e3:
        raise ValueError(
            f"--uncertainty samples decays on the universal curves (perigee up to {top:.1f} km, apogee up to "
            f"{apogee_top:.1f} km here); this orbit ({perigee_km - offset_km:.1f} x {apogee_km - offset_km:.1f} km) "
            "is above them: drop --uncertainty for its lifetime (and --rule's verdict) by the averaged equations"
        )


def _input_files(args: argparse.Namespace) -> list[tuple[str, str | None]]:
    """The files a lifetime reads, with their flags: never to be written over."""
    files = (("--tle", getattr(args, "tle", None)), ("--batch", args.batch), ("--solar-csv", args.solar_csv))
    return [(f"the input file of {name}", path) for name, path in files]


class YearsBar:
    """The years a dated decay has flown, on a terminal: drawn once the decay has run `YearsBar.AFTER_S`.

    A cold decay over decades computes their air (38 s for a 700 km cubesat); a warm one takes a fraction of
    a second and shows nothing (tqdm is imported only when the bar is drawn). Cleared when closed.
    """

    AFTER_S = 1.0
    #: Seconds between two redrawings.
    EVERY_S = 0.1

    def __init__(self) -> None:
        self.start = self.drawn = time.perf_counter()
        self.bar: Any = None

    def __call__(self, days: float) -> None:
        """The decay has reached ``days`` after its epoch (`orbit_env.lifetime`'s ``progress``)."""
        now = time.perf_counter()
        if self.bar is None:
            if now - self.start < self.AFTER_S:
                return
            from tqdm import tqdm

            self.bar = tqdm(desc="years decayed", bar_format="{desc}: {n:.1f} [{elapsed}]", leave=False)
        elif now - self.drawn < self.EVERY_S:
            return
        self.bar.n, self.drawn = round(days / DAYS_PER_YEAR, 1), now
        self.bar.refresh()

    def close(self) -> None:
        """Clear the bar, if drawn."""
        if self.bar is not None:
            self.bar.close()


def _cmd_lifetime(args: argparse.Namespace) -> int:
    args.inclination_defaulted = args.inclination is None and not getattr(args, "tle", None)
    _check_inclination(args)
    if args.trajectory and not args.batch:
        check_output(args.trajectory, "--trajectory", _input_files(args))
    if args.plot and not args.batch:
        check_figure(args.plot, "--plot", [*_input_files(args), ("the --trajectory file", args.trajectory)])
    uncertain_batch.check_options(args)
    orbit = orbit_inputs.prepare(args)
    scenario = _scenario(args)
    drag = orbit_inputs.satellite_from_args(args, orbit, scenario)
    satellite = drag.satellite
    if args.batch:
        return _lifetime_batch(args, satellite, scenario)
    if args.out:
        raise ValueError("--out goes with --batch (a single lifetime prints; --trajectory writes its history)")
    if args.force:
        raise ValueError("--force goes with --batch --out (it lets the results replace an existing file)")
    if orbit.perigee_km is None or orbit.apogee_km is None:
        raise ValueError("give --perigee and --apogee, --semi-major-axis-km and --eccentricity, --tle, or --batch")
    perigee_km, apogee_km = orbit.sphere_heights_km
    offset = orbit.offset_km
    if args.uncertainty:
        _check_on_the_curves(perigee_km, apogee_km, offset)
    air = scenario.in_sphere_heights(orbit.reference, args.inclination)
    years = YearsBar() if air.time_varying and sys.stderr.isatty() else None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SolarTableWarning)  # said below, as the command's warnings are
            result = lifetime(
                perigee_km,
                apogee_km,
                satellite=satellite,
                scenario=air,
                method=args.method,
                inclination_deg=args.inclination,
                progress=years,
            )
    finally:
        if years is not None:
            years.close()
    if scenario.epoch_days is not None:
        _warn_solar_table(scenario, scenario.epoch_days + result.days)
    summary = result.to_dict()
    summary.update(
        perigee_km=orbit.perigee_km,
        apogee_km=orbit.apogee_km,
        height_reference=orbit.reference,
        inclination_deg=args.inclination,
        drag_parameter_m2_kg=satellite.drag_parameter_m2_kg,
        drag_parameter_source=drag.source,
        **drag.report,
    )
    if orbit.elements is not None:
        from orbit_env.analysis.element_set_lifetime import elements_report

        summary.update(elements_report(orbit.elements, result))
    rule = None
    if args.rule is not None:
        rule = check_rule(
            perigee_km,
            apogee_km,
            args.rule,
            satellite=satellite,
            scenario=air,
            inclination_deg=args.inclination,
        )
        summary.update(
            rule_years=args.rule,
            complies=bool(rule.complies[0]),
            new_perigee_km=float(rule.new_perigee_m[0]) / 1e3 - offset,
            dv_m_s=float(rule.dv_m_s[0]),
        )
    band = None
    if args.uncertainty:
        band = orbit_inputs.uncertainty(args, orbit, scenario, satellite, result, summary, drag_sigma(drag))
    if args.trajectory:
        write_csv(args.trajectory, orbit_inputs.history_rows(result.history, offset, result.epoch_days))
    if args.plot:
        from orbit_env.analysis.plots import plot_history

        plot_history(
            result,
            args.plot,
            activity=scenario.activity,
            height_offset_km=offset,
            band_days=band,
            observed=orbit_inputs.history_points(args, result.epoch_days),
        )
    if args.json:
        summary["atmosphere"] = _atmosphere(args, scenario, result=result)
        print(_json(summary))
        return 0
    check_finite(summary, "the result")
    for line in orbit_inputs.orbit_lines(orbit, args.inclination):
        print(line)
    print(orbit_inputs.satellite_line(drag))
    print(f"atmosphere         {_atmosphere(args, scenario, result=result)}")
    print(f"nu                 {result.nu:.4g} m^3/(kg s^2)")
    print(f"revolutions        {result.revolutions:.1f}")
    if result.reentered:
        print(f"lifetime           {_days_text(result.days)}")
        if summary.get("reentry_date"):
            print(f"re-entry           {summary['reentry_date']}")
    else:
        years = result.days / DAYS_PER_YEAR
        print(f"lifetime           still in orbit after {years:.0f} years (where the propagation stops)")
    if args.uncertainty:
        for line in orbit_inputs.uncertainty_lines(summary):
            print(line)
    print(f"perigee velocity   {result.perigee_velocity_m_s:.1f} m/s")
    print(f"method             {result.method}")
    if rule is not None:
        label = f"{args.rule:g}-year rule"  # in the labels' column, whatever the rule's digits
        if rule.complies[0]:
            print(f"{label:<19}complies (re-enters within {args.rule:g} years)")
        else:
            print(
                f"{label:<19}does not comply; smallest burn at apogee: {rule.dv_m_s[0]:.2f} m/s "
                f"(retrograde), lowering the perigee to {rule.new_perigee_m[0] / 1e3 - offset:.1f} km"
            )
    return 0


def _lifetime_batch(args: argparse.Namespace, satellite: Satellite, scenario: Scenario) -> int:
    from concurrent.futures.process import BrokenProcessPool

    from orbit_env.analysis.catalogue import batch_lifetimes, row_start_days
    from orbit_env.analysis.catalogue_io import write_records
    from orbit_env.analysis.catalogue_parts import parts_folder

    if not args.out:
        raise ValueError("--batch needs --out CSV for the results")
    if args.perigee is not None or args.apogee is not None:
        raise ValueError("--batch reads the orbits from the file; do not give --perigee/--apogee")
    if args.semi_major_axis_km is not None or args.eccentricity is not None:
        raise ValueError("--batch reads the orbits from the file; do not give --semi-major-axis-km/--eccentricity")
    for name in ("trajectory", "plot", "json"):
        if given(args, name):
            raise ValueError(f"{flag(name)} applies to a single lifetime, not to --batch")
    if args.method is not None:
        raise ValueError("--batch always uses the universal curves; do not give --method")
    check_output(args.out, "--out", _input_files(args), force=args.force)
    start = time.perf_counter()
    orbits = orbit_inputs.read_orbits(args, satellite, scenario)
    air = scenario.in_sphere_heights(args.height_reference, args.inclination)
    if args.uncertainty:
        try:
            joined = uncertain_batch.run(args, orbits, air)
        except (KeyboardInterrupt, BrokenProcessPool, OSError) as stop:
            if isinstance(stop, OSError) and not parts_folder(args.out).is_dir():
                raise  # nothing computed yet: the error alone
            if isinstance(stop, KeyboardInterrupt):
                why = "stopped"
            elif isinstance(stop, BrokenProcessPool):
                why = f"a worker process died ({stop})"
            else:  # a full disk: the file named, as any command's file errors, and what was kept said
                why = f"error: {in_files(stop, args)}"
            print(
                f"{PROG}: {why}; the finished chunks are kept in {parts_folder(args.out)}: the same command "
                "resumes from them",
                file=sys.stderr,
            )
            return 130 if isinstance(stop, KeyboardInterrupt) else 2
        rows, ok, first, max_days = joined.rows, joined.ok, joined.first_status, joined.max_days
    else:
        records, summary = batch_lifetimes(
            orbits.rows,
            orbits.perigee_m,
            orbits.apogee_m,
            orbits.drag_parameter_m2_kg,
            orbits.inclination_deg,
            orbits.status,
            air,
            rule_years=args.rule,
            progress=not args.no_progress,
            epoch_days=row_start_days(orbits, scenario, getattr(args, "rows_own_epochs", False)),
        )
        records = orbit_inputs.records_in_reference(records, args.height_reference)
        write_records(args.out, records, replace=args.force)  # a file another command wrote meanwhile is kept
        rows, ok = summary.rows, summary.ok
        first = next((record["status"] for record in records if record["status"] != "ok"), None)
        max_days = max((float(record["days"]) for record in records if record["days"]), default=0.0)
    if scenario.epoch_days is not None:
        _warn_solar_table(scenario, scenario.epoch_days + max_days)
    elapsed = time.perf_counter() - start
    print(
        f"wrote {rows} rows to {args.out} ({ok} with lifetimes, {rows - ok} with a "
        f"status message) in {elapsed:.2f} s; atmosphere {_atmosphere(args, scenario, batch=True)}"
    )
    if ok == rows:
        return 0
    # Exit status 1: the results file is complete, but some rows have no lifetime (documented in
    # docs/how-to/catalogue.md); one line on stderr says how many and the first reason.
    print(
        f"{PROG}: {rows - ok} of {rows} rows have no lifetime (first: {first}); "
        f"the status column of {args.out} says why for each",
        file=sys.stderr,
    )
    return 1


def _cmd_fit_density(args: argparse.Namespace) -> int:
    from orbit_env.analysis.density_fit import fit_density_scale, read_observations, reentry_days

    args.inclination_defaulted = args.inclination is None
    _check_inclination(args)
    if args.inclination is None:
        args.inclination = 0.0
    observations = read_observations(args.observations)
    # Activity held constant, or a synthetic cycle, has no dates to start from; a --solar-csv table's days do.
    solar_given = any(given(args, name) for name in ("f107", "f107a", "ap", "solar_cycle"))
    if observations.axis == "date" and args.epoch is not None and not solar_given:
        # The first observation's date, as typed (a day, no time): the air from that observation's moment.
        if math.floor(unix_days(args.epoch)) == math.floor(float(observations.days[0])):
            args.epoch = None
    if observations.axis == "date" and args.epoch is None and not solar_given:
        # Dated observations: the air of their days, the real Sun from the first (as a TLE's epoch does).
        if args.atmosphere is None:
            args.atmosphere = DATED_AIR
        if "epoch" in air_model(args.atmosphere).options:
            args.epoch = str(np.datetime64(round(float(observations.days[0]) * 86400.0), "s"))
    if args.atmosphere is None:
        args.atmosphere = DATED_AIR if args.epoch is not None else DEFAULT_AIR
    satellite = _satellite(args)
    scenario = _scenario(args)
    reentry = None if args.reentry is None else reentry_days(args.reentry, observations, "--reentry")
    for name in ("reentry_sigma_days", "height_sigma_km"):
        if reentry is None and given(args, name):
            raise ValueError(f"{flag(name)} is an uncertainty of a fit to a re-entry: it goes with --reentry")
    fit = fit_density_scale(
        observations,
        satellite=satellite,
        scenario=scenario,
        inclination_deg=args.inclination,
        reentry=args.reentry,  # as typed: a date without a time is a day
        reentry_sigma_days=REENTRY_SIGMA_DAYS if args.reentry_sigma_days is None else args.reentry_sigma_days,
        height_sigma_km=HEIGHT_SIGMA_KM if args.height_sigma_km is None else args.height_sigma_km,
    )
    if scenario.epoch_days is not None:  # the decay runs to the re-entry, or to the last observation
        last = float(observations.days[-1]) if reentry is None else reentry
        _warn_solar_table(scenario, scenario.epoch_days + last - float(observations.days[0]))
    # The scale belongs to the drag parameter it was fitted with: both are said.
    drag = DragSource(satellite, SOURCE_SATELLITE if orbit_inputs.satellite_inputs(args).given else SOURCE_DEFAULT)
    if args.json:
        summary = {**fit.to_dict(), "atmosphere": _atmosphere(args, scenario)}
        summary.update(drag_parameter_m2_kg=satellite.drag_parameter_m2_kg, drag_parameter_source=drag.source)
        print(_json(summary))
        return 0
    check_finite(fit.to_dict(), "the fit")
    low68, high68 = fit.interval(0.68)
    low95, high95 = fit.interval(0.95)
    print(orbit_inputs.satellite_line(drag))
    print(f"atmosphere         {_atmosphere(args, scenario)}")
    print(f"data               {fit.description}")
    print(f"density scale      {fit.scale:.4g} (68%: {low68:.4g} to {high68:.4g}; 95%: {low95:.4g} to {high95:.4g})")
    if fit.residual_rms_km is not None:
        print(f"residuals          {fit.residual_rms_km:.3g} km rms")
    return 0


def _add_satellite_options(parser: argparse.ArgumentParser, shapes: bool = False) -> None:
    group = parser.add_argument_group("satellite")
    from_sets = "; with --tle and no satellite given, the drag comes from the element sets" if shapes else ""
    group.add_argument("--cx", type=number, help=f"drag coefficient (default 2.0{from_sets})")
    group.add_argument("--mass", type=number, metavar="KG", help="mass [kg] (with --area; default the paper's 10 kg)")
    group.add_argument("--area", type=number, metavar="M2", help="reference area [m^2] (default 0.5 m sphere)")
    group.add_argument("--mass-per-area", type=number, metavar="KG_M2", help="transverse load G/F [kg/m^2]")
    if shapes:
        orbit_inputs.add_shape_options(group)


def _add_atmosphere_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("atmosphere")
    group.add_argument(
        "--atmosphere",
        choices=tuple(AIR_MODELS),
        help=f"density model (default: {DATED_AIR} with an epoch or a TLE, else {DEFAULT_AIR})",
    )
    group.add_argument("--rho100", type=number, metavar="KG_M3", help="paper: density at 100 km (default: calibrated)")
    group.add_argument("--density-scale", type=number, default=1.0, help="multiply the density (default 1)")
    group.add_argument(
        "--rho0", type=number, metavar="KG_M3", help="exponential: density at --h0-km (all three, or none: orbital law)"
    )
    group.add_argument("--h0-km", type=number, metavar="KM", help="exponential: reference height (with --rho0)")
    group.add_argument("--scale-height-km", type=number, metavar="KM", help="exponential: scale height (with --rho0)")
    group.add_argument(
        "--f107",
        type=number,
        metavar="SFU",
        help=f"msis: daily F10.7, constant (default {DEFAULT_ACTIVITY.f107_sfu:g})",
    )
    group.add_argument("--f107a", type=number, metavar="SFU", help="msis: 81-day mean F10.7 (default: --f107)")
    group.add_argument(
        "--ap",
        type=number,
        help=f"msis: daily Ap (default {DEFAULT_ACTIVITY.ap:g}; {DEFAULT_AP:g} for a CSV without an ap column)",
    )
    group.add_argument("--solar-csv", metavar="CSV", help="msis: F10.7 (f107a, ap) by date (see orbit_env.decay.solar)")
    group.add_argument("--solar-cycle", action="store_true", help="msis: the built-in smooth solar cycle")
    group.add_argument("--cycle-phase", type=number, metavar="0-1", help="msis: cycle phase at --epoch (0 = minimum)")
    group.add_argument(
        "--epoch",
        metavar="DATE",
        help="msis: the orbit's date (YYYY-MM-DD, a time THH:MM in UTC or with its zone; YYYY-MM: the 15th): "
        "follow the season and the activity from then on",
    )
    group.add_argument(
        "--msis-version",
        choices=tuple(MSIS_VERSION_CHOICES),
        help="msis: NRLMSIS version (default 2.1; 00 = NRLMSISE-00)",
    )
    group.add_argument(
        "--daily-ap",
        action="store_true",
        help="msis with --epoch: the daily Ap every day (default: storm days, any 3-hourly ap >= 48 in the day "
        "or the 57 h before, take NRLMSIS's storm-time mode with the record's 3-hourly ap)",
    )
    group.add_argument("--node-local-time", type=number, metavar="HOURS", help="msis: Sun-synchronous node local time")
    group.add_argument(
        "--chunk-days",
        type=number,
        metavar="DAYS",
        help=f"msis with --epoch: time step [days] (default {DEFAULT_CHUNK_DAYS:g})",
    )
    group.add_argument(
        "--rotating-atmosphere",
        action="store_true",
        help="air co-rotates with the Earth (the default under msis; paper and exponential: still air)",
    )
    group.add_argument(
        "--still-air", action="store_true", help="msis: air that does not turn with the Earth (to compare)"
    )
    group.add_argument(
        "--inclination", type=number, metavar="DEG", help="inclination (rotating air; msis latitudes; default 0)"
    )


def add_parsers(sub: Any) -> None:
    """The ``lifetime`` and ``fit-density`` commands."""
    life = sub.add_parser("lifetime", help="lifetime of a satellite on an orbit, to re-entry at 100 km perigee")
    life.add_argument(
        "--perigee", type=number, metavar="KM", help="perigee height [km] of the orbit flown, above --height-reference"
    )
    life.add_argument("--apogee", type=number, metavar="KM", help="apogee height [km] of the orbit flown")
    orbit_inputs.add_orbit_options(life)
    _add_satellite_options(life, shapes=True)
    life.add_argument(
        "--method",
        choices=METHODS,
        default=None,
        help="averaged ODE, universal curves, or direct (default: curves for orbits on them, perigee up to "
        "1100 km and apogee up to 4000 km, in the paper's atmosphere and NRLMSIS; averaged otherwise)",
    )
    _add_atmosphere_options(life)
    life.add_argument("--rule", type=number, metavar="YEARS", help="disposal rule: re-entry within YEARS (25, 5)")
    life.add_argument(
        "--batch",
        metavar="FILE",
        help="lifetimes of every orbit in a CSV file, or of every object in a file of element sets, TLE or OMM "
        "(each object's sets its history; see orbit_env.analysis.catalogue)",
    )
    life.add_argument("--out", type=output_file, metavar="CSV", help="with --batch: the results file")
    life.add_argument(
        "--force",
        action="store_true",
        help="with --batch: replace an existing --out file (with --uncertainty: and delete another run's parts)",
    )
    life.add_argument("--no-progress", action="store_true", help="with --batch: no progress bar")
    life.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="with --uncertainty: processes for the solar nodes of a dated decay, with --batch for the chunks of "
        "rows (default: all cores, os.cpu_count(); the results do not depend on it)",
    )
    life.add_argument(
        "--address",
        metavar="RAY_ADDRESS",
        help="with --batch --uncertainty: run the chunks as Ray tasks on this cluster ('local': start a local Ray; "
        "the cluster extra); the same file as a local run",
    )
    orbit_inputs.add_uncertainty_options(life)
    life.add_argument("--json", action="store_true", help="print one JSON object")
    life.add_argument("--trajectory", type=output_file, metavar="CSV", help="write the decay history to a CSV file")
    life.add_argument("--plot", type=output_file, metavar="PNG", help="plot the decay history")
    life.set_defaults(func=_cmd_lifetime)

    fit = sub.add_parser("fit-density", help="density scale factor from an observed decay (the paper's section 4)")
    fit.add_argument("observations", metavar="OBS_CSV", help="observed orbits: date (or days), perigee_km, apogee_km")
    fit.add_argument(
        "--reentry",
        metavar="DATE|DAYS",
        help="observed re-entry, on the observations' time axis (a date, or days with a 'days' column): "
        "fit it from the first orbit",
    )
    fit.add_argument(
        "--reentry-sigma-days", type=number, help=f"with --reentry: its uncertainty (default {REENTRY_SIGMA_DAYS:g})"
    )
    fit.add_argument(
        "--height-sigma-km",
        type=number,
        help=f"with --reentry: uncertainty of the first orbit's heights (default {HEIGHT_SIGMA_KM:g})",
    )
    _add_satellite_options(fit)
    _add_atmosphere_options(fit)
    fit.add_argument("--json", action="store_true", help="print one JSON object")
    fit.set_defaults(func=_cmd_fit_density)
