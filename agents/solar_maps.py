"""Where the solar task's policies burn: one held-out mission, and burn maps by solar phase.

``python -m orbit_env.agents.solar_maps --out-mission docs/solar-mission.png --out-maps
docs/solar-burn-maps.png`` flies the shipped PPO and the optimum (the per-episode DP, which knows
the Sun's future) on the evaluation's missions of the test split (`orbit_env.agents.evaluate.EVAL_SEED`,
the missions of ``orbit-env evaluate --env OrbitRaisingSolar-v0``) and draws:

* one mission (by default the one where the optimum's return leads PPO's most): perigee and
  apogee heights, the burns and the disposal burn of each, and the Sun's F10.7 over the mission;
* burn maps: the share of the months each policy burns, by the perigee height at the month's
  start and the phase, counted over every month flown with propellant left.

The solar phase is read two ways: the years since the last solar-cycle minimum
(`CYCLE_MINIMA`, the dates of the smoothed sunspot number's minima), which the optimum's plan
can use and no agent sees; and the trailing 81-day mean of F10.7 on the day before the month,
which the agent observes. A third map reads the mission's month: where a policy burns early,
the phase of its burns is the phase of the missions' starts.

Units as the figures show them: heights in km, burns in m/s, F10.7 in sfu; days are the task's
clock days (`orbit_env.envs.solar_task.date_of`). Measured readings: docs/solar-task.md.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.agents.solar import Flown, fly
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.solar import unix_days
from orbit_env.envs import SOLAR_EVAL_SPLIT, SOLAR_SPLITS, solar_task
from orbit_env.envs.solar_task import SolarStep, SolarTask
from orbit_env.envs.state import BatchState

FloatArray = NDArray[np.float64]

#: Minima of solar cycles 19-25 (SILSO, the 13-month smoothed sunspot number; month's middle day):
#: the first day of each cycle, from which `years_since_minimum` counts.
CYCLE_MINIMA = ("1954-04-15", "1964-10-15", "1976-03-15", "1986-09-15", "1996-08-15", "2008-12-15", "2019-12-15")
#: Bin edges of the burn maps: perigee height [km]; the phases: years since the last minimum (to the
#: longest cycle's length, `years_edges`), the observed 81-day F10.7 [sfu], and the mission's month.
PERIGEE_EDGES_KM = np.arange(220.0, 561.0, 20.0)
F107_EDGES_SFU = np.array([60.0, 70.0, 80.0, 90.0, 100.0, 115.0, 130.0, 150.0, 175.0, 260.0])
MONTH_EDGES = np.array([0.0, 1.0, 2.0, 3.0, 6.0, 12.0, 18.0, 24.0, 36.0, 48.0, 61.0])
#: The phases' axes in the burn maps, and their labels.
PHASE_LABELS = {
    "years": "years since the last solar minimum",
    "f107": "F10.7, 81-day mean, observed [sfu]",
    "month": "month of the mission",
}
#: Cells of a burn map with fewer months than this are left blank (their share is noise).
MIN_MONTHS = 20
_FLOWN_FIELDS = tuple(field.name for field in fields(Flown))


@dataclass(frozen=True)
class Flights:
    """Missions flown month by month (rows: missions; columns: each step's start, then the mission's end).

    Heights and the tank are read at each step's start (before its burn) and after the last step;
    NaN once the satellite has re-entered. ``burn_m_s`` is the perigee burn made at each step's
    start (NaN where the satellite was already down); the disposal burn is the one at the end.
    """

    start_day: FloatArray  # (n,) clock day of the mission's first day
    perigee_km: FloatArray  # (n, H + 1)
    apogee_km: FloatArray  # (n, H + 1)
    dv_left_m_s: FloatArray  # (n, H + 1)
    burn_m_s: FloatArray  # (n, H)
    disposal_m_s: FloatArray  # (n,)
    flown: Flown

    def step_days(self, task: SolarTask) -> FloatArray:
        """The clock day of each step's start and of the mission's end, (n, H + 1)."""
        steps = np.arange(self.perigee_km.shape[1])
        return self.start_day[:, None] + steps[None, :] * task.mission.block_days

    def take(self, index: Any) -> Flights:
        """The missions at ``index`` (an array of rows)."""
        flown = Flown(*(getattr(self.flown, name)[index] for name in _FLOWN_FIELDS))
        return Flights(
            self.start_day[index],
            self.perigee_km[index],
            self.apogee_km[index],
            self.dv_left_m_s[index],
            self.burn_m_s[index],
            self.disposal_m_s[index],
            flown,
        )


class StepRecorder:
    """`orbit_env.agents.solar.fly`'s ``on_step``: each mission's heights, tank and burns, month by month."""

    def __init__(self, task: SolarTask, start: BatchState) -> None:
        horizon = task.config.horizon_steps
        self.start_day = start.start_day.copy()
        self.perigee_km = np.full((start.size, horizon + 1), np.nan)
        self.apogee_km = np.full((start.size, horizon + 1), np.nan)
        self.dv_left_m_s = np.full((start.size, horizon + 1), np.nan)
        self.burn_m_s = np.full((start.size, horizon), np.nan)
        self.disposal_m_s = np.zeros(start.size)
        self._write(np.arange(start.size), 0, start)

    def _write(self, rows: NDArray[np.intp], column: NDArray[np.intp] | int, state: BatchState) -> None:
        self.perigee_km[rows, column] = state.perigee_m / 1e3
        self.apogee_km[rows, column] = state.apogee_m / 1e3
        self.dv_left_m_s[rows, column] = state.dv_left_m_s

    def __call__(self, rows: NDArray[np.intp], state: BatchState, result: SolarStep) -> None:
        """Record one step of the missions at ``rows`` (``state`` after it)."""
        done = state.steps.astype(np.intp)  # the step just flown is done - 1
        self.burn_m_s[rows, done - 1] = result.burn_m_s
        self.disposal_m_s[rows] += result.disposal_m_s
        up = ~result.terminated
        self._write(rows[up], done[up], state.take(np.flatnonzero(up)))

    def flights(self, flown: Flown) -> Flights:
        """The recorded flights with their outcome."""
        return Flights(
            self.start_day, self.perigee_km, self.apogee_km, self.dv_left_m_s, self.burn_m_s, self.disposal_m_s, flown
        )


def fly_recorded(task: SolarTask, options: Mapping[str, Any], act: Callable[[BatchState], FloatArray]) -> Flights:
    """`orbit_env.agents.solar.fly`, recording every month of every mission."""
    n = len(options["start_day"])
    recorder = StepRecorder(task, solar_task.start(task, np.random.default_rng(0), n, options))
    return recorder.flights(fly(task, options, act, on_step=recorder))


def fly_optimum(task: SolarTask, options: Mapping[str, Any], progress: Callable[[int], None] | None = None) -> Flights:
    """The optimum's flights (`orbit_env.agents.solar_dp.SolarDP`, one DP per mission: 1-2 s each on one core)."""
    from orbit_env.agents.solar_dp import SolarDP

    flights = []
    for i, day in enumerate(options["start_day"]):
        one = {name: np.asarray(values)[i : i + 1] for name, values in options.items()}
        flights.append(fly_recorded(task, one, SolarDP(task, float(day)).burns_m_s))
        if progress is not None:
            progress(i + 1)
    return concatenate(flights)


def concatenate(flights: list[Flights]) -> Flights:
    """Flights of several batches as one."""
    flown = Flown(*(np.concatenate([getattr(f.flown, name) for f in flights]) for name in _FLOWN_FIELDS))
    return Flights(
        np.concatenate([f.start_day for f in flights]),
        np.concatenate([f.perigee_km for f in flights]),
        np.concatenate([f.apogee_km for f in flights]),
        np.concatenate([f.dv_left_m_s for f in flights]),
        np.concatenate([f.burn_m_s for f in flights]),
        np.concatenate([f.disposal_m_s for f in flights]),
        flown,
    )


def years_since_minimum(task: SolarTask, days: FloatArray) -> FloatArray:
    """Years from the last solar-cycle minimum (`CYCLE_MINIMA`) to each clock day."""
    minima = np.array([task.clock.day_of(unix_days(date)) for date in CYCLE_MINIMA], dtype=np.float64)
    days = np.asarray(days, dtype=np.float64)
    last = np.searchsorted(minima, days, side="right") - 1
    if np.any(last < 0):
        raise ValueError(f"days before the first minimum in CYCLE_MINIMA ({CYCLE_MINIMA[0]}) have no phase")
    return (days - minima[last]) / DAYS_PER_YEAR


def f107_series(task: SolarTask, days: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The record's daily F10.7 and its trailing 81-day mean (what the observation holds) on clock days [sfu]."""
    f107, mean_81d, _, _ = task.clock.daily_indices
    index = np.asarray(days, dtype=np.intp)
    return f107[index], mean_81d[index]


@dataclass(frozen=True)
class BurnMap:
    """Months counted in each (perigee, phase) cell, and the share of them with a perigee burn."""

    perigee_edges_km: FloatArray
    phase_edges: FloatArray
    months: NDArray[np.int64]  # (P, Q)
    burns: NDArray[np.int64]  # (P, Q) months with a burn > 0
    dv_m_s: FloatArray  # (P, Q) the burns' sum [m/s]

    @property
    def share(self) -> FloatArray:
        """Share of the months with a burn (NaN where fewer than `MIN_MONTHS` months)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.months >= MIN_MONTHS, self.burns / self.months, np.nan)


def step_phases(task: SolarTask, flights: Flights) -> dict[str, FloatArray]:
    """Each step's phase, (n, H), for each key of `PHASE_LABELS`.

    ``years``: since the last minimum, at the step's first day; ``f107``: the trailing 81-day mean
    of F10.7 on the day before it (the observation's) [sfu]; ``month``: the step's index.
    """
    days = flights.step_days(task)[:, :-1]
    _, mean_81d = f107_series(task, days - 1.0)
    month = np.broadcast_to(np.arange(days.shape[1], dtype=np.float64), days.shape)
    return {"years": years_since_minimum(task, days), "f107": mean_81d, "month": month}


def years_edges(years: FloatArray) -> FloatArray:
    """Whole years from 0 to the last that ``years`` reach (a cycle lasts 10-12 years)."""
    return np.arange(0.0, np.ceil(np.max(years)) + 0.5)


def burn_map(flights: Flights, phase: FloatArray, phase_edges: FloatArray, perigee_edges_km: FloatArray) -> BurnMap:
    """Count the months with propellant left by perigee at the month's start and ``phase`` (n, H), and their burns.

    Months outside the edges are counted in the nearest cell at the edge (none is dropped).
    """
    can_burn = ~np.isnan(flights.burn_m_s) & (flights.dv_left_m_s[:, :-1] > 1e-9)
    perigee = flights.perigee_km[:, :-1][can_burn]
    i = np.clip(np.searchsorted(perigee_edges_km, perigee, side="right") - 1, 0, perigee_edges_km.size - 2)
    j = np.clip(np.searchsorted(phase_edges, phase[can_burn], side="right") - 1, 0, phase_edges.size - 2)
    shape = (perigee_edges_km.size - 1, phase_edges.size - 1)
    burn = flights.burn_m_s[can_burn]
    months = np.zeros(shape, dtype=np.int64)
    burns = np.zeros(shape, dtype=np.int64)
    dv = np.zeros(shape)
    np.add.at(months, (i, j), 1)
    np.add.at(burns, (i, j), (burn > 0.0).astype(np.int64))
    np.add.at(dv, (i, j), burn)
    return BurnMap(perigee_edges_km, phase_edges, months, burns, dv)


def burn_maps(task: SolarTask, flights: Mapping[str, Flights]) -> dict[str, dict[str, BurnMap]]:
    """Each policy's burn maps over each phase of `step_phases` (the same edges for every policy)."""
    phases = {name: step_phases(task, flown) for name, flown in flights.items()}
    edges = {
        "years": years_edges(np.concatenate([phase["years"].ravel() for phase in phases.values()])),
        "f107": F107_EDGES_SFU,
        "month": MONTH_EDGES,
    }
    return {
        name: {key: burn_map(flown, phases[name][key], edges[key], PERIGEE_EDGES_KM) for key in edges}
        for name, flown in flights.items()
    }


def plot_mission(task: SolarTask, flights: Mapping[str, Flights], title: str, path: str) -> None:
    """One mission flown by each policy (each ``Flights`` holds that one mission): heights, burns, F10.7."""
    from orbit_env.optional import pyplot

    plt = pyplot()
    colours = dict(zip(flights, ("tab:blue", "tab:orange", "tab:green"), strict=False))
    first = next(iter(flights.values()))
    days = first.step_days(task)[0]
    dates = solar_task.dates_of(task, days)
    fig, (heights, burns, sun) = plt.subplots(
        3, 1, figsize=(9.0, 7.6), dpi=100, sharex=True, layout="constrained", height_ratios=(2.2, 1.2, 1.2)
    )
    offsets = np.linspace(-4.0, 4.0, len(flights))  # days: side by side markers
    for (name, flown), offset in zip(flights.items(), offsets, strict=True):
        colour = colours[name]
        heights.plot(dates, flown.apogee_km[0], color=colour, lw=1.6, label=f"{name}: apogee")
        heights.plot(dates, flown.perigee_km[0], color=colour, lw=1.2, ls="--", label=f"{name}: perigee")
        if flown.flown.reentered[0]:
            last = int(np.flatnonzero(~np.isnan(flown.perigee_km[0]))[-1])
            heights.plot(
                dates[last], flown.perigee_km[0, last], "x", color=colour, ms=9, mew=2, label=f"{name}: re-enters"
            )
        made = flown.burn_m_s[0] > 0.0
        total = np.nansum(flown.burn_m_s[0])
        step_dates = dates[:-1][made] + np.timedelta64(int(offset), "D")
        burns.vlines(step_dates, 0.0, flown.burn_m_s[0][made], color=colour, lw=2.0)
        burns.plot(step_dates, flown.burn_m_s[0][made], "o", color=colour, ms=5, label=f"{name}: {total:.0f} m/s")
        end = dates[-1] + np.timedelta64(int(offset), "D")
        burns.vlines(end, 0.0, flown.disposal_m_s[0], color=colour, lw=2.0)
        burns.plot(
            end, flown.disposal_m_s[0], "*", color=colour, ms=12, label=f"disposal {flown.disposal_m_s[0]:.1f} m/s"
        )
    for ax in (heights, burns, sun):
        ax.axvline(dates[-1], color="0.4", lw=0.8, ls=":")
    heights.text(dates[-1], 0.02, "end: the rule ", transform=heights.get_xaxis_transform(), ha="right", fontsize=8)
    heights.set_ylabel("height [km]")
    heights.legend(fontsize=8, ncol=2, loc="lower left")
    heights.set_title(title, fontsize=10)
    burns.set_ylabel("burn [m/s]")
    burns.set_ylim(0.0, None)
    burns.legend(
        fontsize=8, loc="upper left", ncol=len(flights), title="perigee burns (o), disposal (*)", title_fontsize=8
    )
    all_days = np.arange(days[0], days[-1] + 1.0)
    f107, mean_81d = f107_series(task, all_days)
    all_dates = solar_task.dates_of(task, all_days)
    sun.plot(all_dates, f107, color="0.7", lw=0.6, label="F10.7, daily")
    sun.plot(all_dates, mean_81d, color="k", lw=1.4, label="81-day mean (trailing: observed)")
    sun.set_ylabel("F10.7 [sfu]")
    sun.legend(fontsize=8, loc="upper left")
    sun.set_xlabel("date")
    fig.savefig(path)
    plt.close(fig)


def plot_burn_maps(maps: Mapping[str, Mapping[str, BurnMap]], title: str, path: str) -> None:
    """The share of months with a burn: one row per phase, one column per policy, and the last less the first."""
    from matplotlib.colors import TwoSlopeNorm

    from orbit_env.optional import pyplot

    plt = pyplot()
    names = list(maps)
    keys = list(maps[names[0]])
    fig, axes = plt.subplots(
        len(keys),
        len(names) + 1,
        figsize=(3.9 * (len(names) + 1) + 1.2, 3.3 * len(keys) + 0.4),
        dpi=90,
        layout="constrained",
        squeeze=False,
    )
    for row, key in enumerate(keys):
        first = maps[names[0]][key]
        x = np.arange(first.phase_edges.size)  # cells of equal width, labelled by their edges
        top = max(np.nanmax(np.nan_to_num(maps[name][key].share, nan=0.0)) for name in names)
        top = max(np.ceil(top * 20.0) / 20.0, 0.05)
        for col, name in enumerate(names):
            one = maps[name][key]
            image = axes[row, col].pcolormesh(x, one.perigee_edges_km, one.share, cmap="viridis", vmin=0.0, vmax=top)
            axes[row, col].set_title(
                f"{name}: a burn in {one.burns.sum() / one.months.sum():.1%} of {one.months.sum()} months",
                fontsize=9,
            )
        diff = maps[names[-1]][key].share - first.share
        shown = max(float(np.nanmax(np.abs(diff), initial=0.0)), 0.01)
        contrast = axes[row, -1].pcolormesh(
            x, first.perigee_edges_km, diff, cmap="RdBu_r", norm=TwoSlopeNorm(0.0, -shown, shown)
        )
        axes[row, -1].set_title(f"{names[-1]} less {names[0]}", fontsize=9)
        for ax in axes[row]:
            ax.set_xticks(x, [f"{edge:g}" for edge in first.phase_edges], fontsize=7)
            ax.set_xlabel(PHASE_LABELS[key], fontsize=9)
            ax.tick_params(axis="y", labelsize=8)
        axes[row, 0].set_ylabel("perigee at the month's start [km]", fontsize=9)
        fig.colorbar(image, ax=list(axes[row, :-1]), label="share of months with a burn", shrink=0.9)
        fig.colorbar(contrast, ax=axes[row, -1], label="difference in share", shrink=0.9)
    fig.suptitle(f"{title}; blank: fewer than {MIN_MONTHS} months", fontsize=10)
    fig.savefig(path)
    plt.close(fig)


def pick_mission(flights: Mapping[str, Flights], leader: str, follower: str) -> int:
    """The mission where ``leader``'s return exceeds ``follower``'s most (the first of ties)."""
    return int(np.argmax(flights[leader].flown.returns - flights[follower].flown.returns))


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """The module's docstring as written, and each option's default."""


def main(argv: list[str] | None = None) -> None:
    """Fly PPO and the optimum on the test split's missions; draw one mission and the burn maps."""
    from orbit_env.agents.evaluate import EVAL_SEED, load_model
    from orbit_env.agents.solar import by_model, starts
    from orbit_env.envs import SOLAR_ENV_ID
    from orbit_env.envs.solar_task import SolarMission, date_of

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=HelpFormatter)
    parser.add_argument("--out-mission", default="solar-mission.png", help="the one mission's figure (PNG)")
    parser.add_argument("--out-maps", default="solar-burn-maps.png", help="the burn maps' figure (PNG)")
    parser.add_argument("--episodes", type=int, default=200, help="missions flown (one DP each: 1-2 s)")
    parser.add_argument("--seed", type=int, default=EVAL_SEED, help="seed of the missions (evaluate's)")
    parser.add_argument("--split", default=SOLAR_EVAL_SPLIT, choices=SOLAR_SPLITS, help="the record's split")
    parser.add_argument(
        "--mission", type=int, default=None, help="the mission drawn (an index); None: where dp leads ppo most"
    )
    parser.add_argument("--model", default=None, help="a PPO model in place of the shipped one")
    args = parser.parse_args(argv)
    if args.episodes < 1:
        raise ValueError(f"--episodes={args.episodes} is invalid; allowed: at least 1")
    if args.mission is not None and not 0 <= args.mission < args.episodes:
        raise ValueError(f"--mission={args.mission} is invalid; allowed: 0 to {args.episodes - 1}")
    task = SolarTask(mission=SolarMission(solar_split=args.split))
    options = starts(task, args.episodes, args.seed)
    loaded = load_model(SOLAR_ENV_ID, args.model)
    assert loaded is not None  # the solar env ships a model
    say = f"dp: solving and flying {args.episodes} missions, one DP each"
    print(say, flush=True)
    flights = {
        "dp (optimum)": fly_optimum(
            task, options, lambda done: print(f"  {done}/{args.episodes}", flush=True) if done % 50 == 0 else None
        ),
        "ppo": fly_recorded(task, options, by_model(task, loaded[1])),
    }
    print(f"{args.episodes} {args.split} missions (seed {args.seed}):")
    for name, flown in flights.items():
        early = np.nansum(flown.burn_m_s[:, :6]) / max(np.nansum(flown.burn_m_s), 1e-9)
        burnt = np.nansum(flown.burn_m_s, axis=1).mean()
        print(
            f"  {name}: return {flown.flown.returns.mean():.1f} d, dv {flown.flown.dv_m_s.mean():.1f} m/s "
            f"(perigee burns {burnt:.1f} m/s, {early:.0%} of it in the first 6 months)"
        )
    gap = flights["dp (optimum)"].flown.returns - flights["ppo"].flown.returns
    if args.mission is None:
        index, why = pick_mission(flights, "dp (optimum)", "ppo"), "dp's largest lead over ppo"
    else:
        index, why = args.mission, "--mission"
    one = {name: flown.take(np.array([index])) for name, flown in flights.items()}
    start = date_of(task, one["ppo"].start_day[0])
    title = (
        f"{args.split} mission {index} of {args.episodes} (seed {args.seed}), from {start}: "
        + ", ".join(f"{name} returns {flown.flown.returns[0]:.1f} d" for name, flown in one.items())
        + f"\n({why}; dp - ppo over the {args.episodes}: mean {gap.mean():.1f} d, median {np.median(gap):.1f} d)"
    )
    print(title)
    plot_mission(task, one, title, args.out_mission)
    maps = burn_maps(task, flights)
    plot_burn_maps(
        maps, f"where each policy burns: {args.episodes} {args.split} missions (seed {args.seed})", args.out_maps
    )
    print("share of months with a burn, by phase (bins from their lower edges):")
    for key in PHASE_LABELS:
        edges = maps["ppo"][key].phase_edges
        print(f"  {PHASE_LABELS[key]}: " + " ".join(f"{edge:>6g}" for edge in edges[:-1]))
        for name, by_phase in maps.items():
            one_map = by_phase[key]
            per_phase = one_map.burns.sum(axis=0) / np.maximum(one_map.months.sum(axis=0), 1)
            print(f"    {name:>14}: " + " ".join(f"{x:6.3f}" for x in per_phase))


if __name__ == "__main__":
    main()
