"""The ``orbit-env`` command line: lifetimes, Table II and Fig. 2.

Every error a user can cause ends in one line on stderr and exit status 2.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

from orbit_env.api import METHODS, lifetime, make_satellite
from orbit_env.atmosphere import RHO100_CALIBRATED_KG_M3

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


def _cmd_lifetime(args: argparse.Namespace) -> int:
    satellite = make_satellite(args.cx, args.mass, args.area, args.mass_per_area)
    result = lifetime(
        args.perigee,
        args.apogee,
        satellite=satellite,
        method=args.method,
        rho100_kg_m3=args.rho100,
        density_scale=args.density_scale,
        rotating_atmosphere=args.rotating_atmosphere,
        inclination_deg=args.inclination,
    )
    if args.trajectory:
        _write_csv(args.trajectory, result.history.rows())
    if args.plot:
        from orbit_env.plotting import plot_history

        plot_history(result, args.plot)
    if args.json:
        print(json.dumps(result.to_dict()))
        return 0
    rho100 = args.rho100 if args.rho100 is not None else RHO100_CALIBRATED_KG_M3
    print(f"orbit              {result.perigee_km:g} x {result.apogee_km:g} km")
    print(
        f"satellite          c_x {satellite.drag_coefficient:g}, {satellite.mass_kg:g} kg, "
        f"{satellite.area_m2:.4g} m^2 (G/F = {satellite.mass_per_area_kg_m2:.4g} kg/m^2)"
    )
    print(f"atmosphere         paper, rho(100 km) = {rho100:.4g} kg/m^3 x {args.density_scale:g}")
    print(f"nu                 {result.nu:.4g} m^3/(kg s^2)")
    print(f"revolutions        {result.revolutions:.1f}")
    print(f"lifetime           {result.days:.2f} days ({result.days / 365.25:.2f} years)")
    print(f"perigee velocity   {result.perigee_velocity_m_s:.1f} m/s")
    print(f"method             {result.method}")
    return 0


def _cmd_table2(args: argparse.Namespace) -> int:
    from orbit_env.table2 import compare_table2

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
    from orbit_env.plotting import plot_fig2

    out = plot_fig2(args.out)
    print(f"wrote {out}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The full ``orbit-env`` parser."""
    parser = _Parser(prog=PROG, description="Satellite decay by Okhotsimsky, Eneev and Taratynova (1957).")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    life = sub.add_parser("lifetime", help="lifetime of a satellite on an orbit, to re-entry at 100 km perigee")
    life.add_argument("--perigee", type=float, required=True, metavar="KM", help="perigee height [km]")
    life.add_argument("--apogee", type=float, required=True, metavar="KM", help="apogee height [km]")
    life.add_argument("--cx", type=float, default=2.0, help="drag coefficient (default 2.0)")
    life.add_argument("--mass", type=float, metavar="KG", help="mass [kg] (with --area; default the paper's 10 kg)")
    life.add_argument("--area", type=float, metavar="M2", help="reference area [m^2] (default 0.5 m sphere)")
    life.add_argument("--mass-per-area", type=float, metavar="KG_M2", help="transverse load G/F [kg/m^2]")
    life.add_argument("--rho100", type=float, metavar="KG_M3", help="density at 100 km (default: calibrated)")
    life.add_argument("--density-scale", type=float, default=1.0, help="multiply the density (default 1)")
    life.add_argument("--method", choices=METHODS, default="averaged", help="averaged ODE, universal curves, or direct")
    life.add_argument("--rotating-atmosphere", action="store_true", help="air co-rotates with the Earth")
    life.add_argument("--inclination", type=float, default=0.0, metavar="DEG", help="inclination (rotating air)")
    life.add_argument("--json", action="store_true", help="print one JSON object")
    life.add_argument("--trajectory", metavar="CSV", help="write the decay history to a CSV file")
    life.add_argument("--plot", metavar="PNG", help="plot the decay history")
    life.set_defaults(func=_cmd_lifetime)

    table = sub.add_parser("table2", help="all 351 cells of the paper's Table II beside ours")
    fmt = table.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="a JSON list of cells")
    fmt.add_argument("--csv", action="store_true", help="CSV")
    table.set_defaults(func=_cmd_table2)

    fig = sub.add_parser("fig2", help="draw the paper's Fig. 2")
    fig.add_argument("--out", default="fig2.png", metavar="PNG", help="output file (default fig2.png)")
    fig.set_defaults(func=_cmd_fig2)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, ImportError, OSError) as error:
        message = str(error).splitlines()[0] if str(error) else type(error).__name__
        print(f"{PROG}: error: {message}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
