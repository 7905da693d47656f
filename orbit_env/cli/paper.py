"""``orbit-env table2`` and ``orbit-env fig2``: the paper reproduced."""

from __future__ import annotations

import argparse
import csv
import json
import sys
from typing import Any

from orbit_env.cli.common import check_figure, output_file


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

    check_figure(args.out, "--out")
    out = plot_fig2(args.out)
    print(f"wrote {out}")
    return 0


def add_parsers(sub: Any) -> None:
    """The ``table2`` and ``fig2`` commands."""
    table = sub.add_parser("table2", help="all 351 cells of the paper's Table II beside ours")
    fmt = table.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="a JSON list of cells")
    fmt.add_argument("--csv", action="store_true", help="CSV")
    table.set_defaults(func=_cmd_table2)

    fig = sub.add_parser("fig2", help="draw the paper's Fig. 2")
    fig.add_argument(
        "--out", type=output_file, default="fig2.png", metavar="PNG", help="output file (default fig2.png)"
    )
    fig.set_defaults(func=_cmd_fig2)
