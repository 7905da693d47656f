"""The ``orbit-env`` command line: lifetimes (one orbit or a CSV batch), rules, density fits, Table II, Fig. 2.

Every error a user can cause ends in one line on stderr and exit status 2. An
error in a value names the flag and the value as typed (``--perigee 50 is out of
range; allowed: 100 to 50000 km``): the API raises :class:`orbit_env.checks.InputError`
naming its parameter, and :data:`FLAGS` maps the parameter to the flag at one place.
Heights are in km here and converted to SI at once; the batch CSV format is in
:mod:`orbit_env.analysis.catalogue`, the solar CSV format in :mod:`orbit_env.decay.solar`, the
observations of ``fit-density`` in :mod:`orbit_env.analysis.density_fit`.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from collections.abc import Sequence
from typing import Any, NoReturn

from orbit_env.analysis.lifetime import METHODS, Satellite, check_rule, lifetime, make_satellite
from orbit_env.analysis.scenario import ATMOSPHERES, Scenario
from orbit_env.checks import InputError
from orbit_env.decay.solar import DEFAULT_AP, ConstantActivity, CycleActivity, SolarActivity, read_solar_csv, unix_days
from orbit_env.physics.atmosphere import ExponentialAtmosphere

PROG = "orbit-env"


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def _write_csv(path: str, rows: list[dict[str, Any]]) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


_MSIS_ONLY = ("f107", "f107a", "ap", "solar_csv", "solar_cycle", "cycle_phase", "epoch", "node_local_time")
_EXPONENTIAL_ONLY = ("rho0", "h0_km", "scale_height_km")


def _given(args: argparse.Namespace, name: str) -> bool:
    value = getattr(args, name)
    return value is not None and value is not False


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


class _Typed(float):
    """A number from the command line that remembers how it was typed (for messages)."""

    text: str


def _number(text: str) -> float:
    value = _Typed(text)
    value.text = text.strip()
    return value


_number.__name__ = "number"  # argparse says "invalid number value: 'abc'"

#: The API's parameter names (as :class:`~orbit_env.checks.InputError` gives them) -> the flag's
#: argparse dest and, for a flag in other units than the parameter, the factor to the flag's unit and
#: that unit. ``scale`` is an atmosphere's, ``phase`` :meth:`CycleActivity.with_phase`'s.
FLAGS: dict[str, tuple[str, float, str | None]] = {
    "perigee_km": ("perigee", 1.0, None),
    "apogee_km": ("apogee", 1.0, None),
    "drag_coefficient": ("cx", 1.0, None),
    "mass_kg": ("mass", 1.0, None),
    "area_m2": ("area", 1.0, None),
    "mass_per_area_kg_m2": ("mass_per_area", 1.0, None),
    "rho100_kg_m3": ("rho100", 1.0, None),
    "density_scale": ("density_scale", 1.0, None),
    "scale": ("density_scale", 1.0, None),
    "rho0_kg_m3": ("rho0", 1.0, None),
    "h0_m": ("h0_km", 1e-3, "km"),
    "scale_height_m": ("scale_height_km", 1e-3, "km"),
    "f107_sfu": ("f107", 1.0, None),
    "f107a_sfu": ("f107a", 1.0, None),
    "ap": ("ap", 1.0, None),
    "phase": ("cycle_phase", 1.0, None),
    "ascending_node_local_time_h": ("node_local_time", 1.0, None),
    "chunk_days": ("chunk_days", 1.0, None),
    "inclination_deg": ("inclination", 1.0, None),
    "rule_years": ("rule", 1.0, None),
    "reentry_sigma_days": ("reentry_sigma_days", 1.0, None),
    "height_sigma_km": ("height_sigma_km", 1.0, None),
}


def _in_flags(error: InputError, args: argparse.Namespace) -> str:
    """The error in the command line's words: the flag, the value as typed, the flag's unit."""
    if error.name not in FLAGS or error.index is not None or not hasattr(args, FLAGS[error.name][0]):
        return str(error)  # not a flag's value (a file's cell, an element of a table)
    dest, factor, unit = FLAGS[error.name]
    typed = getattr(args, dest)
    return error.message(
        _flag(dest),
        value_text=typed.text if isinstance(typed, _Typed) else None,
        scale=factor,
        unit=unit,
        rename=lambda name: _flag(FLAGS[name][0]) if name in FLAGS else name,
    )


def _scenario(args: argparse.Namespace) -> Scenario:
    """The atmosphere and solar activity chosen on the command line."""
    kind = args.atmosphere
    for name in _MSIS_ONLY:
        if kind != "msis" and _given(args, name):
            raise ValueError(f"{_flag(name)} applies to --atmosphere msis")
    for name in _EXPONENTIAL_ONLY:
        if kind != "exponential" and _given(args, name):
            raise ValueError(f"{_flag(name)} applies to --atmosphere exponential")
    if kind != "paper" and args.rho100 is not None:
        raise ValueError("--rho100 applies to --atmosphere paper")
    common = {
        "density_scale": args.density_scale,
        "rotating_atmosphere": args.rotating_atmosphere,
        "chunk_days": args.chunk_days,
    }
    if kind == "paper":
        return Scenario("paper", rho100_kg_m3=args.rho100, **common)
    if kind == "exponential":
        exponential = ExponentialAtmosphere(
            1.3 if args.rho0 is None else args.rho0,
            0.0 if args.h0_km is None else args.h0_km * 1e3,
            8.5e3 if args.scale_height_km is None else args.scale_height_km * 1e3,
        )
        return Scenario(
            "exponential",
            rho0_kg_m3=exponential.rho0_kg_m3,
            h0_m=exponential.h0_m,
            scale_height_m=exponential.scale_height_m,
            **common,
        )
    epoch = None if args.epoch is None else unix_days(args.epoch)
    activity: SolarActivity
    if args.solar_csv and args.solar_cycle:
        raise ValueError("give either --solar-csv or --solar-cycle, not both")
    if (args.solar_csv or args.solar_cycle) and (args.f107 is not None or args.f107a is not None):
        raise ValueError("--f107/--f107a set constant activity; they do not combine with --solar-csv/--solar-cycle")
    if args.cycle_phase is not None and not args.solar_cycle:
        raise ValueError("--cycle-phase applies to --solar-cycle")
    if args.solar_csv:
        activity = read_solar_csv(args.solar_csv, default_ap=DEFAULT_AP if args.ap is None else args.ap)
        if epoch is None:
            epoch = activity.start_days
    elif args.solar_cycle:
        if epoch is None:
            raise ValueError("--solar-cycle needs --epoch (the orbit's date; it sets the phase and the season)")
        activity = CycleActivity() if args.cycle_phase is None else CycleActivity.with_phase(args.cycle_phase, epoch)
    else:
        f107 = 150.0 if args.f107 is None else args.f107
        activity = ConstantActivity(
            f107, f107 if args.f107a is None else args.f107a, 15.0 if args.ap is None else args.ap
        )
    return Scenario(
        "msis", activity=activity, epoch_days=epoch, ascending_node_local_time_h=args.node_local_time, **common
    )


def _satellite(args: argparse.Namespace) -> Satellite:
    return make_satellite(args.cx, args.mass, args.area, args.mass_per_area)


def _cmd_lifetime(args: argparse.Namespace) -> int:
    satellite = _satellite(args)
    scenario = _scenario(args)
    if args.batch:
        return _lifetime_batch(args, satellite, scenario)
    if args.out:
        raise ValueError("--out goes with --batch (a single lifetime prints; --trajectory writes its history)")
    if args.perigee is None or args.apogee is None:
        raise ValueError("give --perigee and --apogee (or --batch CSV)")
    # Default method: the averaged ODE (the reference) for a fixed atmosphere; for activity that changes
    # in time, the time-stepped curves (the averaged reference then rebuilds NRLMSIS every day: minutes).
    method = args.method or ("curves" if scenario.time_varying else "averaged")
    options: dict[str, Any] = {
        "satellite": satellite,
        "method": method,
        "rotating_atmosphere": args.rotating_atmosphere,
        "inclination_deg": args.inclination,
    }
    if scenario.atmosphere == "paper":
        options.update(rho100_kg_m3=args.rho100, density_scale=args.density_scale)
    elif scenario.atmosphere == "exponential":
        options["atmosphere"] = ExponentialAtmosphere(
            scenario.rho0_kg_m3, scenario.h0_m, scenario.scale_height_m, args.density_scale
        )
    else:
        options.update(
            activity=scenario.solar,
            epoch=scenario.epoch_days,
            density_scale=args.density_scale,
            ascending_node_local_time_h=args.node_local_time,
            chunk_days=args.chunk_days,
        )
    result = lifetime(args.perigee, args.apogee, **options)
    summary = result.to_dict()
    rule = None
    if args.rule is not None:
        rule = check_rule(
            args.perigee,
            args.apogee,
            args.rule,
            satellite=satellite,
            scenario=scenario,
            inclination_deg=args.inclination,
        )
        summary.update(
            rule_years=args.rule,
            complies=bool(rule.complies[0]),
            new_perigee_km=float(rule.new_perigee_m[0]) / 1e3,
            dv_m_s=float(rule.dv_m_s[0]),
        )
    if args.trajectory:
        _write_csv(args.trajectory, result.history.rows())
    if args.plot:
        from orbit_env.analysis.plots import plot_history

        plot_history(result, args.plot)
    if args.json:
        print(json.dumps(summary))
        return 0
    print(f"orbit              {result.perigee_km:g} x {result.apogee_km:g} km")
    print(
        f"satellite          c_x {satellite.drag_coefficient:g}, {satellite.mass_kg:g} kg, "
        f"{satellite.area_m2:.4g} m^2 (G/F = {satellite.mass_per_area_kg_m2:.4g} kg/m^2)"
    )
    print(f"atmosphere         {scenario.describe(args.inclination)}")
    print(f"nu                 {result.nu:.4g} m^3/(kg s^2)")
    print(f"revolutions        {result.revolutions:.1f}")
    print(f"lifetime           {result.days:.2f} days ({result.days / 365.25:.2f} years)")
    print(f"perigee velocity   {result.perigee_velocity_m_s:.1f} m/s")
    print(f"method             {result.method}")
    if rule is not None:
        if rule.complies[0]:
            print(f"{args.rule:g}-year rule       complies (re-enters within {args.rule:g} years)")
        else:
            print(
                f"{args.rule:g}-year rule       does not comply; smallest burn at apogee: {rule.dv_m_s[0]:.2f} m/s "
                f"(retrograde), lowering the perigee to {rule.new_perigee_m[0] / 1e3:.1f} km"
            )
    return 0


def _lifetime_batch(args: argparse.Namespace, satellite: Satellite, scenario: Scenario) -> int:
    from orbit_env.analysis.catalogue import batch_lifetimes, read_batch, write_records

    if not args.out:
        raise ValueError("--batch needs --out CSV for the results")
    if args.perigee is not None or args.apogee is not None:
        raise ValueError("--batch reads the orbits from the file; do not give --perigee/--apogee")
    for name in ("trajectory", "plot", "json"):
        if _given(args, name):
            raise ValueError(f"{_flag(name)} applies to a single lifetime, not to --batch")
    if args.method is not None:
        raise ValueError("--batch always uses the universal curves; do not give --method")
    start = time.perf_counter()
    rows, hp, ha, c, inc, status = read_batch(
        args.batch, satellite.drag_coefficient, satellite.drag_parameter_m2_kg, args.inclination
    )
    records, summary = batch_lifetimes(
        rows, hp, ha, c, inc, status, scenario, rule_years=args.rule, progress=not args.no_progress
    )
    write_records(args.out, records)
    elapsed = time.perf_counter() - start
    print(
        f"wrote {summary.rows} rows to {args.out} ({summary.ok} with lifetimes, {summary.rows - summary.ok} with a "
        f"status message) in {elapsed:.2f} s; atmosphere {scenario.describe(args.inclination)}"
    )
    return 0


def _cmd_table2(args: argparse.Namespace) -> int:
    from orbit_env.paper.table2 import compare_table2

    comparison = compare_table2()
    rows = comparison.rows()
    summary = comparison.summary()
    if args.json:
        print(json.dumps(rows))
        return 0
    if args.csv:
        writer = csv.DictWriter(sys.stdout, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
        return 0
    print(f"{'perigee':>7} {'apogee':>6} {'nu paper':>9} {'nu':>10} {'error':>7} {'v paper':>7} {'v':>7}")
    for row in rows:
        flags = "  nu misprint?" if row["nu_misprint"] else ""
        flags += "  v misprint?" if row["v_perigee_misprint"] else ""
        print(
            f"{row['perigee_km']:7.0f} {row['apogee_km']:6.0f} {row['nu_paper']:9.4g} {row['nu']:10.4g} "
            f"{row['rel_error']:+7.1%} {row['v_perigee_paper']:7.0f} {row['v_perigee']:7.1f}{flags}"
        )
    print(
        f"{summary['cells']} cells: median |error| {summary['median_abs_rel_error']:.1%}, "
        f"90th percentile {summary['p90_abs_rel_error']:.1%}, max {summary['max_abs_rel_error']:.1%}; "
        f"{summary['nu_misprints']} nu and {summary['v_perigee_misprints']} velocity cells flagged as likely "
        f"misprints (without them: median {summary['median_abs_rel_error_without_misprints']:.1%}, "
        f"90th percentile {summary['p90_abs_rel_error_without_misprints']:.1%})"
    )
    print(
        f"with the paper's own Euler scheme (5/10 km steps in p, rho(100 km) = "
        f"{summary['paper_scheme_rho100_kg_m3']:.3g} kg/m^3): "
        f"median {summary['paper_scheme_median_abs_rel_error']:.1%}, "
        f"90th percentile {summary['paper_scheme_p90_abs_rel_error']:.1%}"
    )
    return 0


def _cmd_fig2(args: argparse.Namespace) -> int:
    from orbit_env.paper.figures import plot_fig2

    out = plot_fig2(args.out)
    print(f"wrote {out}")
    return 0


def _add_satellite_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("satellite")
    group.add_argument("--cx", type=_number, default=2.0, help="drag coefficient (default 2.0)")
    group.add_argument("--mass", type=_number, metavar="KG", help="mass [kg] (with --area; default the paper's 10 kg)")
    group.add_argument("--area", type=_number, metavar="M2", help="reference area [m^2] (default 0.5 m sphere)")
    group.add_argument("--mass-per-area", type=_number, metavar="KG_M2", help="transverse load G/F [kg/m^2]")


def _add_atmosphere_options(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("atmosphere")
    group.add_argument("--atmosphere", choices=ATMOSPHERES, default="paper", help="density model (default paper)")
    group.add_argument("--rho100", type=_number, metavar="KG_M3", help="paper: density at 100 km (default: calibrated)")
    group.add_argument("--density-scale", type=_number, default=1.0, help="multiply the density (default 1)")
    group.add_argument("--rho0", type=_number, metavar="KG_M3", help="exponential: density at --h0-km (default 1.3)")
    group.add_argument("--h0-km", type=_number, metavar="KM", help="exponential: reference height (default 0)")
    group.add_argument("--scale-height-km", type=_number, metavar="KM", help="exponential: scale height (default 8.5)")
    group.add_argument("--f107", type=_number, metavar="SFU", help="msis: daily F10.7, constant (default 150)")
    group.add_argument("--f107a", type=_number, metavar="SFU", help="msis: 81-day mean F10.7 (default: --f107)")
    group.add_argument("--ap", type=_number, help="msis: daily Ap (default 15; 12 for a CSV without an ap column)")
    group.add_argument("--solar-csv", metavar="CSV", help="msis: F10.7 (f107a, ap) by date (see orbit_env.decay.solar)")
    group.add_argument("--solar-cycle", action="store_true", help="msis: the built-in smooth solar cycle")
    group.add_argument("--cycle-phase", type=_number, metavar="0-1", help="msis: cycle phase at --epoch (0 = minimum)")
    group.add_argument(
        "--epoch", metavar="DATE", help="msis: the orbit's date: follow the season and the activity from then on"
    )
    group.add_argument("--node-local-time", type=_number, metavar="HOURS", help="msis: Sun-synchronous node local time")
    group.add_argument("--chunk-days", type=_number, default=20.0, help="msis with --epoch: time step (default 20)")
    group.add_argument("--rotating-atmosphere", action="store_true", help="air co-rotates with the Earth")
    group.add_argument(
        "--inclination", type=_number, default=0.0, metavar="DEG", help="inclination (rotating air; msis latitudes)"
    )


def _cmd_train(args: argparse.Namespace) -> int:
    from orbit_env.agents.train import train

    result = train(args.config, args.out, total_timesteps=args.timesteps, progress=not args.no_progress)
    print(f"trained {result.timesteps} timesteps in {result.seconds:.0f} s")
    print(f"model: {result.model_path}  (tensorboard --logdir {result.log_dir})")
    return 0


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from orbit_env.agents.evaluate import all_policies, evaluate, format_table, paired_difference, plot_returns

    def say(name: str) -> None:
        if not args.json:
            print(f"  running {name} ...", file=sys.stderr)

    policies = all_policies(args.env, model_path=args.model, include_dp=not args.no_dp, progress=say)
    results, table = evaluate(args.env, policies, args.episodes, args.seed, progress=say)
    if args.plot:
        plot_returns(results, args.env, args.plot)
    # PPO against the best hand-coded policy, then against the optimum.
    paired = {
        "paired_difference": paired_difference(results),
        "paired_to_dp": paired_difference(results, baseline="dp"),
    }
    if args.json:
        out = {"env": args.env, "episodes": args.episodes, "seed": args.seed, "policies": table}
        out.update({key: pair for key, pair in paired.items() if pair is not None})
        print(json.dumps(out))
    else:
        found = [pair for pair in paired.values() if pair is not None]
        print(format_table(args.env, args.episodes, args.seed, table, found))
    return 0


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The full ``orbit-env`` parser."""
    parser = _Parser(prog=PROG, description="Satellite decay by Okhotsimsky, Eneev and Taratynova (1957).")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    life = sub.add_parser("lifetime", help="lifetime of a satellite on an orbit, to re-entry at 100 km perigee")
    life.add_argument("--perigee", type=_number, metavar="KM", help="perigee height [km]")
    life.add_argument("--apogee", type=_number, metavar="KM", help="apogee height [km]")
    _add_satellite_options(life)
    life.add_argument(
        "--method",
        choices=METHODS,
        default=None,
        help="averaged ODE, universal curves, or direct (default: averaged; curves when the solar activity "
        "changes in time, where the averaged reference takes minutes)",
    )
    _add_atmosphere_options(life)
    life.add_argument("--rule", type=_number, metavar="YEARS", help="disposal rule: re-entry within YEARS (25, 5)")
    life.add_argument(
        "--batch", metavar="CSV", help="lifetimes of every orbit in a CSV file (see orbit_env.analysis.catalogue)"
    )
    life.add_argument("--out", metavar="CSV", help="with --batch: the results file")
    life.add_argument("--no-progress", action="store_true", help="with --batch: no progress bar")
    life.add_argument("--json", action="store_true", help="print one JSON object")
    life.add_argument("--trajectory", metavar="CSV", help="write the decay history to a CSV file")
    life.add_argument("--plot", metavar="PNG", help="plot the decay history")
    life.set_defaults(func=_cmd_lifetime)

    fit = sub.add_parser("fit-density", help="density scale factor from an observed decay (the paper's section 4)")
    fit.add_argument("observations", metavar="OBS_CSV", help="observed orbits: date (or days), perigee_km, apogee_km")
    fit.add_argument("--reentry", metavar="DATE", help="observed re-entry date: fit it from the first orbit")
    fit.add_argument("--reentry-sigma-days", type=_number, default=0.5, help="uncertainty of --reentry (default 0.5)")
    fit.add_argument(
        "--height-sigma-km", type=_number, default=1.0, help="with --reentry: uncertainty of the first orbit's heights"
    )
    _add_satellite_options(fit)
    _add_atmosphere_options(fit)
    fit.add_argument("--json", action="store_true", help="print one JSON object")
    fit.set_defaults(func=_cmd_fit_density)

    table = sub.add_parser("table2", help="all 351 cells of the paper's Table II beside ours")
    fmt = table.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="a JSON list of cells")
    fmt.add_argument("--csv", action="store_true", help="CSV")
    table.set_defaults(func=_cmd_table2)

    fig = sub.add_parser("fig2", help="draw the paper's Fig. 2")
    fig.add_argument("--out", default="fig2.png", metavar="PNG", help="output file (default fig2.png)")
    fig.set_defaults(func=_cmd_fig2)
    tr = sub.add_parser("train", help="train PPO on the vector environment (config file: agents/ppo.toml)")
    tr.add_argument("--config", metavar="TOML", help="hyperparameter file (default: the shipped agents/ppo.toml)")
    tr.add_argument("--out", default="runs/ppo", metavar="DIR", help="logs, checkpoints, model.zip (default runs/ppo)")
    tr.add_argument("--timesteps", type=_positive_int, metavar="N", help="override the config's total_timesteps")
    tr.add_argument("--no-progress", action="store_true", help="no progress bar")
    tr.set_defaults(func=_cmd_train)

    from orbit_env.agents.evaluate import EVAL_EPISODES, EVAL_SEED

    ev = sub.add_parser("evaluate", help="every policy on the same seeded episodes: when does a burn pay off?")
    ev.add_argument("--env", default="OrbitRaising-v0", metavar="ID", help="environment id (default OrbitRaising-v0)")
    ev.add_argument(
        "--episodes", type=_positive_int, default=EVAL_EPISODES, metavar="N", help=f"episodes (default {EVAL_EPISODES})"
    )
    ev.add_argument(
        "--seed", type=int, default=EVAL_SEED, metavar="S", help=f"seed of the episodes (default {EVAL_SEED})"
    )
    ev.add_argument("--model", metavar="ZIP", help="PPO model (default: the shipped one for the environment)")
    ev.add_argument("--no-dp", action="store_true", help="skip the dynamic-programming optimum")
    ev.add_argument("--json", action="store_true", help="print one JSON object")
    ev.add_argument("--plot", metavar="PNG", help="box plot of the returns")
    ev.set_defaults(func=_cmd_evaluate)
    return parser


def _cmd_fit_density(args: argparse.Namespace) -> int:
    from orbit_env.analysis.density_fit import fit_density_scale, read_observations

    satellite = _satellite(args)
    scenario = _scenario(args)
    observations = read_observations(args.observations)
    fit = fit_density_scale(
        observations,
        satellite=satellite,
        scenario=scenario,
        inclination_deg=args.inclination,
        reentry=args.reentry,
        reentry_sigma_days=args.reentry_sigma_days,
        height_sigma_km=args.height_sigma_km,
    )
    if args.json:
        print(json.dumps(fit.to_dict()))
        return 0
    low68, high68 = fit.interval(0.68)
    low95, high95 = fit.interval(0.95)
    print(f"atmosphere         {scenario.describe(args.inclination)}")
    print(f"data               {fit.description}")
    print(f"density scale      {fit.scale:.4g} (68%: {low68:.4g} to {high68:.4g}; 95%: {low95:.4g} to {high95:.4g})")
    if fit.residual_rms_km is not None:
        print(f"residuals          {fit.residual_rms_km:.3g} km rms")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, ImportError, OSError) as error:
        text = _in_flags(error, args) if isinstance(error, InputError) else str(error)
        message = text.splitlines()[0] if text else type(error).__name__
        print(f"{PROG}: error: {message}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
