"""Plot a compliance screen: each row's probability of re-entering within the rule against its mean altitude.

Reads the results of ``orbit-env lifetime --batch FILE --out RESULTS --uncertainty --rule Y``
(columns ``perigee_km``, ``apogee_km``, ``compliance_probability``,
``complies_with_confidence``, ``days_p5/p50/p95``) and draws two panels: the probability
with the 90% confidence line, and the 5-50-95% lifetimes with the rule's years. Rows
without a lifetime are left out. docs/compliance-screen.png is

    python benchmarks/plot_compliance_screen.py screen.csv docs/compliance-screen.png --rule 5

on the screen of docs/how-to/catalogue.md.
"""

from __future__ import annotations

import argparse
import csv

from orbit_env.analysis.uncertainty import RULE_CONFIDENCE
from orbit_env.constants import DAYS_PER_YEAR


def main() -> None:
    """Read the results, write the PNG."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="the results CSV of --batch --uncertainty --rule")
    parser.add_argument("png", help="the plot")
    parser.add_argument("--rule", type=float, required=True, help="the rule's years (as given to --rule)")
    args = parser.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(args.results, newline="") as handle:
        rows = [row for row in csv.DictReader(handle) if row["status"] == "ok" and row["compliance_probability"]]
    altitude = [0.5 * (float(row["perigee_km"]) + float(row["apogee_km"])) for row in rows]
    probability = [float(row["compliance_probability"]) for row in rows]
    passes = [row["complies_with_confidence"] == "true" for row in rows]
    years = {
        p: [float(row[f"days_p{p}"]) / DAYS_PER_YEAR if row[f"days_p{p}"] else float("nan") for row in rows]
        for p in (5, 50, 95)
    }
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(5.5, 5.0), sharex=True, dpi=90)
    top.plot(altitude, probability, color="0.6", lw=1, zorder=1)
    top.scatter(altitude, probability, c=["tab:green" if ok else "tab:red" for ok in passes], zorder=2)
    top.axhline(RULE_CONFIDENCE, color="k", ls="--", lw=1)
    top.text(min(altitude), RULE_CONFIDENCE - 0.1, f"{RULE_CONFIDENCE:.0%} confidence", fontsize=8)
    top.set_ylabel(f"P(re-entry within {args.rule:g} years)")
    top.set_ylim(-0.05, 1.05)
    top.set_title("compliance screen (green: complies at 90% confidence)", fontsize=9)
    low = [m - p for m, p in zip(years[50], years[5], strict=True)]
    high = [p - m for m, p in zip(years[50], years[95], strict=True)]
    bottom.errorbar(altitude, years[50], yerr=[low, high], fmt="o", color="tab:blue", capsize=3, ms=4)
    bottom.axhline(args.rule, color="k", ls="--", lw=1)
    bottom.text(min(altitude), args.rule * 1.1, f"{args.rule:g}-year rule", fontsize=8)
    bottom.set_yscale("log")
    bottom.set_ylabel("lifetime, 5-50-95% [years]")
    bottom.set_xlabel("mean altitude [km]")
    figure.tight_layout()
    figure.savefig(args.png)


if __name__ == "__main__":
    main()
