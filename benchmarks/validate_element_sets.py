"""Re-entry predictions from real element sets against the observed re-entries (issue 27, item 6).

Run: python benchmarks/validate_element_sets.py [--history] [--no-uncertainty] [--samples 200]
[--objects 37820,32789] [--limit-cases N] [--out rows.csv] [--plot fig.png] [--json]
(needs pymsis; one case costs one ``orbit-env lifetime`` run per mode, a few seconds each: the
cost per case is printed at the end).

The data are ``benchmarks/data/reentry_tles/`` (its README gives every set's and date's source): real
two-line element sets, oldest first, and the observed re-entry in ``objects.csv``. The two Planet Doves
whose notes start with "FLAGGED" (41479, 41480: differential drag acts like a manoeuvre) are left out
unless ``--include-flagged``.

Observed re-entry: the instant where ``reentry_utc`` gives a time (uncertainty 0); a day-only date
(SATCAT) is taken at noon UTC of that day with an uncertainty of +-0.5 day. The lead time of a set,
and the observed remaining life ``L``, is that instant minus the set's epoch, in days.

Cases (the rule): the usable window holds the sets with ``7 <= L <= 1096`` days (7 days to 3 years).
Per object up to 3 sets of the window: the latest (shortest lead), the set whose lead is closest to
25% of the longest lead in the window (the earlier one on a tie), and the earliest (longest lead);
duplicates are dropped, so an object with one or two sets in the window gives one or two cases.

Modes, all through the package's command line run in-process
(``orbit_env.cli.main(["lifetime", "--tle", FILE, "--json", ...])``):

* one set: a file holding the chosen set (a name line and its two lines);
* known shape (``--shapes``): the same file with the satellite as documented in ``shapes.csv`` (its
  mass and its body, tumbling at random: ``--mass M --shape cubesat --form-factor 1U`` or ``--shape box
  --size-m X Y Z``), for the objects listed there; the drag is then the satellite's, not the set's;
* history (``--history``): a file holding the object's sets with epochs from 60 days before the chosen
  set's epoch up to it, the chosen set last; where there are more than 30, 30 evenly spaced in file
  order, always keeping the oldest and the chosen one. A history of one set is not run ("one set
  only"). A command that refuses several sets without ``--batch`` (exit status 2, "... use --batch ...")
  makes the case "history not supported" rather than an error; one whose sets give no fit (no two a
  day apart: the command then predicts from the latest set alone, as in the one-set mode) "no history
  fit".

With ``--uncertainty`` (default on) the same run adds ``--uncertainty --samples N``: the prediction is
read from ``days`` and the 90% band from ``reentry_date_percentiles`` ("5" to "95"), counted from the
set's epoch; the observed re-entry is "in band" when its interval (the instant +- its uncertainty)
meets the band.

Metrics: the error of a case is ``(P - L) / L`` (P the predicted remaining life); per mode, over all
cases and by lead time (< 30 d, 30-180 d, > 180 d): the median |error|, its 90th percentile (linear
interpolation between order statistics, numpy's default), the fraction within +-25% and the fraction
of cases whose band holds the observed re-entry. The goals of issue 27: one set median <= 20%;
histories median <= 10% and 90% of cases within +-25%; the band holds >= 85% of the observed re-entries.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import datetime as dt
import io
import json
import math
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "reentry_tles"
UTC = dt.UTC
#: The usable window: epochs between 7 days and 3 years (1096 days) before the re-entry.
MIN_LEAD_DAYS = 7.0
MAX_LEAD_DAYS = 1096.0
#: The middle case: the set whose lead is closest to this fraction of the window's longest lead.
MIDDLE_FRACTION = 0.25
#: A history: the sets at most this many days older than the chosen one, at most this many of them.
HISTORY_SPAN_DAYS = 60.0
HISTORY_MAX_SETS = 30
#: A day-only re-entry date: noon UTC of that day, +- half a day.
DAY_ONLY_UNCERTAINTY_DAYS = 0.5
#: The "within" threshold of the issue's goals: |error| <= 25% of the remaining life.
WITHIN = 0.25
#: Lead-time buckets [low, high) in days and their labels.
BUCKETS = ((0.0, 30.0, "<30 d"), (30.0, 180.0, "30-180 d"), (180.0, math.inf, ">180 d"))
MODES = ("one set", "history", "known shape")
#: The objects whose mass and body are documented (no deployed appendages): the mode "known shape".
SHAPES_CSV = DATA / "shapes.csv"
#: Status of a case whose history the command line does not accept yet.
HISTORY_NOT_SUPPORTED = "history not supported"
#: Status of a history case whose sets gave no fit: the command predicted from the latest set alone.
NO_HISTORY_FIT = "no history fit"


@dataclass(frozen=True)
class ElementLines:
    """One two-line element set as published, with its epoch."""

    line1: str
    line2: str
    epoch: dt.datetime


@dataclass(frozen=True)
class SpaceObject:
    """An object of the data set: its sets (oldest first) and its observed re-entry."""

    norad: int
    name: str
    reentry: dt.datetime
    reentry_uncertainty_days: float
    flagged: bool
    sets: tuple[ElementLines, ...]

    def lead_days(self, index: int) -> float:
        """Days from the epoch of set ``index`` to the observed re-entry (the observed remaining life)."""
        return days_between(self.sets[index].epoch, self.reentry)


@dataclass(frozen=True)
class Case:
    """A set chosen for a prediction and the prediction in one mode."""

    norad: int
    name: str
    mode: str
    epoch: dt.datetime
    lead_days: float
    observed_uncertainty_days: float
    sets_used: int
    status: str  # "ok", HISTORY_NOT_SUPPORTED, "one set only" or "error: ..."
    predicted_days: float = math.nan
    band_days: tuple[float, float] = (math.nan, math.nan)
    reentered: bool | None = None
    drag_parameter_source: str = ""
    fit_sets: int | None = None  # the sets the command's history fit used (JSON drag_fit.sets)
    seconds: float = 0.0

    @property
    def error(self) -> float:
        """(P - L) / L, NaN without a prediction."""
        return relative_error(self.predicted_days, self.lead_days)

    @property
    def in_band(self) -> bool | None:
        """Whether the band holds the observed re-entry; None without a band."""
        if math.isnan(self.band_days[0]):
            return None
        return inside_band(self.lead_days, self.band_days, self.observed_uncertainty_days)


# ---- reading the data set


def days_between(start: dt.datetime, end: dt.datetime) -> float:
    """``end - start`` in days."""
    return (end - start).total_seconds() / 86400.0


def tle_epoch(line1: str) -> dt.datetime:
    """The epoch of a set from columns 19-32 of line 1 (two-digit year: 57-99 -> 19xx, 00-56 -> 20xx)."""
    yy = int(line1[18:20])
    year = yy + (1900 if yy >= 57 else 2000)
    return dt.datetime(year, 1, 1, tzinfo=UTC) + dt.timedelta(days=float(line1[20:32]) - 1.0)


def read_sets(path: Path) -> tuple[ElementLines, ...]:
    """The two-line sets of a file in file order (blank and name lines skipped)."""
    lines = [line.strip() for line in path.read_text(encoding="ascii").splitlines() if line.strip()]
    sets = []
    for k, line in enumerate(lines[:-1]):
        if line.startswith("1 ") and lines[k + 1].startswith("2 "):
            sets.append(ElementLines(line, lines[k + 1], tle_epoch(line)))
    return tuple(sets)


def observed_reentry(text: str) -> tuple[dt.datetime, float]:
    """The re-entry instant of ``reentry_utc`` and its uncertainty in days (a bare date: noon, +-0.5 d)."""
    if "T" in text:
        when = dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
        return when.astimezone(UTC), 0.0
    day = dt.datetime.fromisoformat(text).replace(tzinfo=UTC)
    return day + dt.timedelta(hours=12), DAY_ONLY_UNCERTAINTY_DAYS


def load_objects(data: Path = DATA) -> list[SpaceObject]:
    """Every object of ``objects.csv`` with its sets, in the file's order."""
    objects = []
    with open(data / "objects.csv", newline="") as handle:
        for row in csv.DictReader(handle):
            norad = int(row["norad"])
            (path,) = data.glob(f"{norad}_*.tle")
            reentry, uncertainty = observed_reentry(row["reentry_utc"])
            if row["reentry_uncertainty_hours"].strip():
                uncertainty = float(row["reentry_uncertainty_hours"]) / 24.0
            objects.append(
                SpaceObject(
                    norad=norad,
                    name=row["name"],
                    reentry=reentry,
                    reentry_uncertainty_days=uncertainty,
                    flagged=row["notes"].startswith("FLAGGED"),
                    sets=read_sets(path),
                )
            )
    return objects


def load_shapes(path: Path = SHAPES_CSV) -> dict[int, list[str]]:
    """NORAD number -> the command line's satellite flags (``--mass`` and the shape) of ``shapes.csv``."""
    with open(path, newline="") as handle:
        return {int(row["norad"]): ["--mass", row["mass_kg"], *row["shape"].split()] for row in csv.DictReader(handle)}


# ---- choosing the cases (pure)


def choose_sets(leads_days: Sequence[float]) -> list[int]:
    """Indices of the sets to predict from, given each set's lead time in days (the module's rule).

    The latest set of the window, the one closest to 25% of the window's longest lead and the earliest,
    without duplicates, in ascending index order; [] if no set lies in the window.
    """
    window = [k for k, lead in enumerate(leads_days) if MIN_LEAD_DAYS <= lead <= MAX_LEAD_DAYS]
    if not window:
        return []
    latest = min(window, key=lambda k: (leads_days[k], -k))
    earliest = max(window, key=lambda k: (leads_days[k], -k))
    target = MIDDLE_FRACTION * leads_days[earliest]
    middle = min(window, key=lambda k: (abs(leads_days[k] - target), -leads_days[k]))
    return sorted({latest, middle, earliest})


def history_indices(epochs_days: Sequence[float], chosen: int) -> list[int]:
    """Indices of the history of set ``chosen``: the sets of the last 60 days up to it, at most 30.

    ``epochs_days`` are the sets' epochs in days (any origin), in file order (oldest first). Sets later
    than the chosen one never enter. More than 30 are thinned to 30 evenly spaced in index, keeping the
    oldest and the chosen set.
    """
    start = epochs_days[chosen] - HISTORY_SPAN_DAYS
    span = [k for k in range(chosen + 1) if start <= epochs_days[k] <= epochs_days[chosen]]
    if len(span) <= HISTORY_MAX_SETS:
        return span
    picks = np.linspace(0, len(span) - 1, HISTORY_MAX_SETS).round().astype(int)
    return [span[p] for p in sorted(set(picks.tolist()))]


# ---- metrics (pure)


def relative_error(predicted_days: float, observed_days: float) -> float:
    """(P - L) / L: the prediction's error as a fraction of the observed remaining life."""
    return (predicted_days - observed_days) / observed_days


def inside_band(observed_days: float, band_days: tuple[float, float], uncertainty_days: float = 0.0) -> bool:
    """Whether the observed remaining life (+- its uncertainty) meets the band [low, high]."""
    low, high = band_days
    return observed_days + uncertainty_days >= low and observed_days - uncertainty_days <= high


def lead_bucket(lead_days: float) -> str:
    """The label of the lead-time bucket of a case."""
    for low, high, label in BUCKETS:
        if low <= lead_days < high:
            return label
    raise ValueError(f"lead time {lead_days} d is in no bucket (negative?)")


def error_metrics(errors: Sequence[float], in_band: Sequence[bool | None] = ()) -> dict[str, float | int]:
    """Median |error|, its 90th percentile, the fraction within +-25% and the band's coverage.

    NaN errors (no prediction) are left out; ``in_band`` entries of None (no band) likewise.
    """
    values = np.abs(np.array([e for e in errors if not math.isnan(e)], dtype=float))
    bands = [b for b in in_band if b is not None]
    return {
        "cases": int(values.size),
        "median_abs_error": float(np.median(values)) if values.size else math.nan,
        "p90_abs_error": float(np.percentile(values, 90.0)) if values.size else math.nan,
        "within_25": float(np.mean(values <= WITHIN)) if values.size else math.nan,
        "band_cases": len(bands),
        "band_coverage": float(np.mean(bands)) if bands else math.nan,
    }


def summarize(cases: Sequence[Case]) -> dict[str, dict]:
    """Per mode: the count of each status, the metrics over all predicted cases and by lead bucket."""
    out: dict[str, dict] = {}
    for mode in MODES:
        mine = [c for c in cases if c.mode == mode]
        if not mine:
            continue
        statuses: dict[str, int] = {}
        for c in mine:
            statuses[c.status] = statuses.get(c.status, 0) + 1
        done = [c for c in mine if c.status == "ok"]
        buckets = {}
        for _, _, label in BUCKETS:
            inside = [c for c in done if lead_bucket(c.lead_days) == label]
            buckets[label] = error_metrics([c.error for c in inside], [c.in_band for c in inside])
        out[mode] = {
            "statuses": statuses,
            "all": error_metrics([c.error for c in done], [c.in_band for c in done]),
            "by_lead": buckets,
        }
    return out


# ---- running the command line


def write_sets(path: Path, name: str, sets: Sequence[ElementLines]) -> None:
    """A three-line file (name line, then the two lines) of each set."""
    path.write_text("".join(f"{name}\n{s.line1}\n{s.line2}\n" for s in sets), encoding="ascii")


def run_cli(argv: list[str]) -> tuple[int, dict | None, str]:
    """``orbit-env`` in-process: exit status, the JSON it printed (if any) and its last stderr line."""
    from orbit_env.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(argv)
        except SystemExit as stop:  # argparse refusing an option
            status = stop.code if isinstance(stop.code, int) else 2
        except Exception as error:  # a crash is a case's result, not the end of the run
            print(f"{type(error).__name__}: {error}", file=sys.stderr)
            status = 1
    message = (err.getvalue().strip().splitlines() or [""])[-1].removeprefix("orbit-env: error: ")
    try:
        return status, json.loads(out.getvalue()), message
    except json.JSONDecodeError:
        return status, None, message


def parse_date(text: str) -> dt.datetime:
    """A date the command prints ("2013-09-17T05:12Z")."""
    return dt.datetime.fromisoformat(text.replace("Z", "+00:00")).astimezone(UTC)


def predict(
    obj: SpaceObject,
    chosen: int,
    mode: str,
    sets: Sequence[int],
    samples: int | None,
    folder: Path,
    drag_from: str | None = None,
    satellite: Sequence[str] = (),
) -> Case:
    """Run one case: the sets ``sets`` of ``obj`` in one file, predicted from set ``chosen``.

    ``satellite``: the mode "known shape"'s flags (`load_shapes`).
    """
    epoch = obj.sets[chosen].epoch
    base = {
        "norad": obj.norad,
        "name": obj.name,
        "mode": mode,
        "epoch": epoch,
        "lead_days": obj.lead_days(chosen),
        "observed_uncertainty_days": obj.reentry_uncertainty_days,
        "sets_used": len(sets),
    }
    if mode == "history" and len(sets) < 2:
        return Case(**base, status="one set only")
    path = folder / f"{obj.norad}_{chosen}_{mode.replace(' ', '_')}.tle"
    write_sets(path, obj.name, [obj.sets[k] for k in sets])
    argv = ["lifetime", "--tle", str(path), "--json"]
    if drag_from and mode == "one set":
        argv += ["--drag-from", drag_from]
    argv += list(satellite)
    if samples:
        argv += ["--uncertainty", "--samples", str(samples)]
    clock = time.perf_counter()
    status, summary, message = run_cli(argv)
    seconds = time.perf_counter() - clock
    if status != 0 or summary is None:
        if mode == "history" and status == 2 and "--batch" in message:
            return Case(**base, status=HISTORY_NOT_SUPPORTED, seconds=seconds)
        return Case(**base, status=f"error: {message or f'exit status {status}'}", seconds=seconds)
    if mode == "history" and summary.get("drag_parameter_source") != "history_fit":
        # No fit (no two sets a day apart): the command predicted from the latest set alone, the one-set case.
        return Case(**base, status=NO_HISTORY_FIT, seconds=seconds)
    # The prediction counts from the epoch the command used (the chosen set's, to the second).
    offset = days_between(epoch, parse_date(summary["epoch"])) if summary.get("epoch") else 0.0
    band = (math.nan, math.nan)
    percentiles = summary.get("reentry_date_percentiles")
    if percentiles:
        # An edge without a date lies beyond the command's horizon (no re-entry in those samples).
        low, high = (percentiles.get(p) for p in ("5", "95"))
        band = (
            days_between(epoch, parse_date(low)) if low else math.inf,
            days_between(epoch, parse_date(high)) if high else math.inf,
        )
    return Case(
        **base,
        status="ok",
        predicted_days=float(summary["days"]) + offset,
        band_days=band,
        reentered=summary.get("reentered"),
        drag_parameter_source=str(summary.get("drag_parameter_source", "")),
        fit_sets=(summary.get("drag_fit") or {}).get("sets"),
        seconds=seconds,
    )


def run_cases(
    objects: Sequence[SpaceObject],
    *,
    history: bool,
    samples: int | None,
    limit: int | None,
    drag_from: str | None = None,
    shapes: dict[int, list[str]] | None = None,
) -> list[Case]:
    """Every chosen case of ``objects`` (one set; the history and the known shape if asked), progress on stderr."""
    plan = [(obj, k) for obj in objects for k in choose_sets([obj.lead_days(i) for i in range(len(obj.sets))])]
    if limit is not None:
        plan = plan[:limit]
    cases: list[Case] = []
    with tempfile.TemporaryDirectory(prefix="element_sets_") as tmp:
        for number, (obj, k) in enumerate(plan, start=1):
            epochs = [days_between(obj.sets[0].epoch, s.epoch) for s in obj.sets]
            runs = [("one set", [k])] + ([("history", history_indices(epochs, k))] if history else [])
            satellite = (shapes or {}).get(obj.norad)
            runs += [("known shape", [k])] if satellite else []
            notes = []
            for mode, sets in runs:
                flags = satellite if mode == "known shape" else ()
                case = predict(obj, k, mode, sets, samples, Path(tmp), drag_from, flags or ())
                cases.append(case)
                what = f"{case.error:+.1%}" if case.status == "ok" else case.status
                notes.append(f"{mode} ({len(sets)} sets) {what} in {case.seconds:.1f} s")
            print(
                f"[{number}/{len(plan)}] {obj.norad} {obj.name[:24]} {obj.sets[k].epoch:%Y-%m-%d} "
                f"lead {obj.lead_days(k):.1f} d: " + "; ".join(notes),
                file=sys.stderr,
                flush=True,
            )
    return cases


# ---- output


def percent(value: float) -> str:
    return "-" if value is None or math.isnan(value) else f"{100.0 * value:.1f}%"


def finite(value):
    """``value`` with every NaN replaced by None, for strict JSON."""
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


def print_table(cases: Sequence[Case]) -> None:
    print(f"{'norad':>6} {'name':<24} {'mode':<11} {'epoch':<16} {'lead d':>8} {'pred d':>9} {'error':>9} {'band':>5}")
    for c in cases:
        predicted = f"{c.predicted_days:9.1f}" if c.status == "ok" else f"{'-':>9}"
        error = f"{100.0 * c.error:+8.1f}%" if c.status == "ok" else f"{'-':>9}"
        band = {None: "-", True: "yes", False: "no"}[c.in_band]
        extra = "" if c.status == "ok" else f"  ({c.status})"
        print(
            f"{c.norad:>6} {c.name[:24]:<24} {c.mode:<11} {c.epoch:%Y-%m-%d %H:%M} {c.lead_days:8.1f} "
            f"{predicted} {error} {band:>5}{extra}"
        )


def print_summary(summary: dict[str, dict]) -> None:
    print(f"\n{'mode':<11} {'lead':<9} {'cases':>5} {'median|e|':>9} {'p90|e|':>9} {'<=25%':>7} {'in band':>12}")
    for mode, parts in summary.items():
        rows = [("all", parts["all"]), *parts["by_lead"].items()]
        for label, m in rows:
            band = f"{percent(m['band_coverage'])} of {m['band_cases']}" if m["band_cases"] else "-"
            print(
                f"{mode:<11} {label:<9} {m['cases']:>5} {percent(m['median_abs_error']):>9} "
                f"{percent(m['p90_abs_error']):>9} {percent(m['within_25']):>7} {band:>12}"
            )
        statuses = ", ".join(f"{n} {s}" for s, n in sorted(parts["statuses"].items()))
        print(f"{mode:<11} statuses: {statuses}")


def write_rows(cases: Sequence[Case], path: str) -> None:
    fields = [
        "norad",
        "name",
        "mode",
        "epoch",
        "lead_days",
        "sets_used",
        "status",
        "predicted_days",
        "error_percent",
        "band_low_days",
        "band_high_days",
        "in_band",
        "reentered",
        "drag_parameter_source",
        "fit_sets",
        "seconds",
    ]
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=fields)
        writer.writeheader()
        for c in cases:
            writer.writerow(
                {
                    "norad": c.norad,
                    "name": c.name,
                    "mode": c.mode,
                    "epoch": c.epoch.strftime("%Y-%m-%dT%H:%M:%SZ"),
                    "lead_days": f"{c.lead_days:.3f}",
                    "sets_used": c.sets_used,
                    "status": c.status,
                    "predicted_days": "" if math.isnan(c.predicted_days) else f"{c.predicted_days:.3f}",
                    "error_percent": "" if math.isnan(c.error) else f"{100.0 * c.error:.2f}",
                    "band_low_days": "" if math.isnan(c.band_days[0]) else f"{c.band_days[0]:.3f}",
                    "band_high_days": "" if math.isnan(c.band_days[1]) else f"{c.band_days[1]:.3f}",
                    "in_band": "" if c.in_band is None else c.in_band,
                    "reentered": "" if c.reentered is None else c.reentered,
                    "drag_parameter_source": c.drag_parameter_source,
                    "fit_sets": "" if c.fit_sets is None else c.fit_sets,
                    "seconds": f"{c.seconds:.2f}",
                }
            )


def plot(cases: Sequence[Case], path: str) -> None:
    """Predicted against observed remaining life (log-log), the diagonal, +-25%, the 90% bands as error bars."""
    try:
        import matplotlib
    except ImportError as error:
        raise ImportError("--plot needs matplotlib: pip install 'orbit-env[plot]'") from error
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [c for c in cases if c.status == "ok"]
    if not done:
        raise ValueError("--plot: no case has a prediction to draw")
    values = [c.lead_days for c in done] + [c.predicted_days for c in done]
    values += [v for c in done for v in c.band_days if math.isfinite(v) and v > 0]
    lim = (0.7 * min(values), 1.4 * max(values))
    fig, ax = plt.subplots(figsize=(6.5, 6.0))
    ax.plot(lim, lim, "k-", lw=0.8, label="predicted = observed")
    for factor in (1.0 - WITHIN, 1.0 + WITHIN):
        ax.plot(lim, [factor * x for x in lim], "k--", lw=0.6)
    ax.plot([], [], "k--", lw=0.6, label="+-25%")
    for mode, color in zip(MODES, ("tab:blue", "tab:orange", "tab:green"), strict=True):
        mine = [c for c in done if c.mode == mode]
        if not mine:
            continue
        x = np.array([c.lead_days for c in mine])
        y = np.array([c.predicted_days for c in mine])
        low = np.array([c.band_days[0] for c in mine])
        high = np.minimum([c.band_days[1] for c in mine], lim[1])  # an edge beyond the horizon: to the frame
        has = ~np.isnan(low)
        if has.any():
            ax.errorbar(
                x[has],
                y[has],
                yerr=[y[has] - low[has], high[has] - y[has]],
                fmt="none",
                ecolor=color,
                alpha=0.5,
                lw=0.8,
                capsize=2,
            )
        ax.plot(x, y, "o", color=color, ms=4, label=f"{mode} ({len(mine)} cases)")
    ax.set(
        xscale="log",
        yscale="log",
        xlim=lim,
        ylim=lim,
        xlabel="observed remaining life [days]",
        ylabel="predicted remaining life [days]",
        title="Re-entry from real element sets (bars: 90% band)",
    )
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", help="comma-separated NORAD numbers to run (default: all not flagged)")
    parser.add_argument("--include-flagged", action="store_true", help="also run the flagged objects")
    parser.add_argument("--history", action="store_true", help="also predict from each case's history")
    parser.add_argument(
        "--shapes", action="store_true", help="also predict with the documented mass and body of shapes.csv's objects"
    )
    parser.add_argument(
        "--uncertainty",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="run with --uncertainty and test the 90%% band (default on)",
    )
    parser.add_argument("--samples", type=int, default=200, help="Monte Carlo samples of the band (default 200)")
    parser.add_argument("--limit-cases", type=int, metavar="N", help="run only the first N cases")
    parser.add_argument(
        "--drag-from", choices=("bstar", "ndot", "bstar-raw"), help="one set: what gives the drag (the CLI's option)"
    )
    parser.add_argument("--out", metavar="CSV", help="write one row per case and mode")
    parser.add_argument("--plot", metavar="PNG", help="predicted against observed remaining life")
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    args = parser.parse_args(argv)
    if args.samples < 2:
        parser.error(f"--samples must be at least 2, got {args.samples}")

    objects = load_objects()
    if args.objects:
        wanted = {int(n) for n in args.objects.split(",") if n.strip()}
        unknown = wanted - {o.norad for o in objects}
        if unknown:
            parser.error(f"--objects: no object {sorted(unknown)} in {DATA / 'objects.csv'}")
        objects = [o for o in objects if o.norad in wanted]
    if not args.include_flagged:
        objects = [o for o in objects if not o.flagged]

    clock = time.perf_counter()
    cases = run_cases(
        objects,
        history=args.history,
        samples=args.samples if args.uncertainty else None,
        limit=args.limit_cases,
        drag_from=args.drag_from,
        shapes=load_shapes() if args.shapes else None,
    )
    total = time.perf_counter() - clock
    summary = summarize(cases)
    # The cost of a case: its one-set run (a refused history costs only the command's parsing).
    run_seconds = [c.seconds for c in cases if c.mode == "one set"]
    cost = {
        "total_seconds": total,
        "cases": len(run_seconds),
        "seconds_per_case_median": float(np.median(run_seconds)) if run_seconds else math.nan,
        "seconds_per_case_mean": float(np.mean(run_seconds)) if run_seconds else math.nan,
        "seconds_per_case_max": float(np.max(run_seconds)) if run_seconds else math.nan,
        "samples": args.samples if args.uncertainty else 0,
    }
    if args.out:
        write_rows(cases, args.out)
    if args.plot:
        plot(cases, args.plot)
    if args.json:
        print(json.dumps(finite({"objects": len(objects), "summary": summary, "cost": cost}), indent=1))
        return 0
    print_table(cases)
    print_summary(summary)
    print(
        f"\n{len(objects)} objects, {cost['cases']} cases in {total:.0f} s; one-set run a case: median "
        f"{cost['seconds_per_case_median']:.1f} s, mean {cost['seconds_per_case_mean']:.1f} s, "
        f"max {cost['seconds_per_case_max']:.1f} s ({cost['samples']} samples of the band)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
