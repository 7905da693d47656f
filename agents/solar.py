"""Yardsticks of the solar task (``OrbitRaisingSolar-v0``): operators' rules, the optimum, the evaluation.

Hand-coded operators' rules act on the observation alone, as an operator would
(`SOLAR_RULES`, in the order of the rows): never burn; burn the whole tank at once; reboost
when the perigee falls below a threshold; reboost when the predicted lifetime falls below a
share of the mission's time left; the greedy look-ahead on the observed activity held constant.
A `Threshold` rule has its threshold (from its ``grid``) and the reserve it keeps tuned on the
train split (`tune`), never on the test split. Each answers SB3's ``predict`` as well as ``actions``. A new
rule is a class here and its entry in `SOLAR_RULES`. The optimum is the per-episode DP
(`orbit_env.agents.solar_dp`), which knows the Sun's future.

`evaluate_solar` scores them all on the same missions (drawn once from a seed; the DP's
episodes solved and flown in worker processes), with any learned agent (`by_model`: the shipped
PPO of ``agents/ppo_solar.toml``, trained on the train split), as ``orbit-env evaluate --env
OrbitRaisingSolar-v0`` prints them.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.agents import VALIDATION_SEED
from orbit_env.agents.evaluate import Episodes, predicted_actions
from orbit_env.agents.protocol import Predicts
from orbit_env.checks import check_int
from orbit_env.constants import REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.envs import DISPOSAL_YEARS, SOLAR_ENV_ID, SOLAR_EVAL_SPLIT, solar_task
from orbit_env.envs import task as task_model
from orbit_env.envs.solar_task import SOLAR_OBS_INDEX, SOLAR_OBS_NAMES, SolarMission, SolarStep, SolarTask
from orbit_env.envs.state import BatchState
from orbit_env.envs.task import DV_SCALE_M_S, HEIGHT_SCALE_M, observation_batch
from orbit_env.physics.orbit import dv_to_lower_perigee_m_s
from orbit_env.workers import worker_pool

FloatArray = NDArray[np.float64]

#: Seed of the tuning missions on the train split, training's validation seed (the evaluation's is
#: `orbit_env.agents.EVAL_SEED`).
TUNE_SEED = VALIDATION_SEED
#: Missions the thresholds are tuned on.
TUNE_EPISODES = 300
#: Perigee thresholds tried [km] and delta-v reserves kept for the disposal [m/s].
PERIGEE_THRESHOLDS_KM = tuple(range(200, 451, 25))
RESERVES_M_S = (0.0, 20.0, 40.0)
#: Shares of the mission's time left below which a predicted lifetime triggers a reboost.
LIFE_SHARES = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 3.0)
#: Bisection steps of the greedy rule's disposal estimate (400 km / 2^20: well under a metre).
GREEDY_BISECTIONS = 20


def largest_burn(task: SolarTask) -> int:
    """The action of the task's largest burn size (what the threshold rules burn)."""
    return len(task.config.burn_sizes_m_s) - 1


def observed(obs: FloatArray, name: str) -> FloatArray:
    """One component of a batch of observations (n, 11) by its name (`orbit_env.envs.solar_task.SOLAR_OBS_NAMES`)."""
    return np.asarray(obs, dtype=np.float64)[:, SOLAR_OBS_INDEX[name]]


class Never(Predicts):
    """Never burn (the disposal burn at the end is the environment's).

    The base of the operators' rules: a rule's ``actions`` maps observations (n, 11) to burn
    sizes' indices; ``predict`` answers SB3's protocol with them, in either solar id's action
    space. ``name`` is the rule's row.
    """

    name = "never"

    def __init__(self, task: SolarTask) -> None:
        self.task = task

    def actions(self, obs: FloatArray) -> NDArray[np.int64]:
        """Action 0 for every observation."""
        return np.zeros(len(obs), dtype=np.int64)

    def actions_of(self, observation: Any) -> Any:
        """`actions` of observations (11,) or (n, 11) in the environment's action space (SB3's ``predict``).

        The burn sizes' indices, or on the continuous twin the Box values that burn the same sizes.

        Raises:
            ValueError: an observation of another shape, or not finite.
        """
        return self.task.encode(self.burns_m_s(observation_batch(observation, len(SOLAR_OBS_NAMES))))

    def burns_m_s(self, obs: FloatArray) -> FloatArray:
        """The burns [m/s] the rule's `actions` (indices of the task's sizes) ask for on observations (n, 11)."""
        return self.task.burn_sizes_m_s[self.actions(obs)]


class AllAtOnce(Never):
    """The largest burn at every step from the start until the tank is empty."""

    name = "all_at_once"

    def actions(self, obs: FloatArray) -> NDArray[np.int64]:
        """The largest burn size for every observation."""
        return np.full(len(obs), largest_burn(self.task), dtype=np.int64)


class Threshold(Never):
    """A reboost rule: the largest burn when a measure falls below ``threshold``, keeping ``reserve_m_s`` [m/s].

    ``grid``: the thresholds `tune` tries (each with every reserve of `RESERVES_M_S`).
    """

    grid: tuple[float, ...] = ()

    def __init__(self, task: SolarTask, threshold: float, reserve_m_s: float) -> None:
        super().__init__(task)
        self.threshold, self.reserve_m_s = threshold, reserve_m_s

    def _spare(self, obs: FloatArray) -> NDArray[np.bool_]:
        """Where the tank holds more than the reserve."""
        return observed(obs, "delta_v_left") * DV_SCALE_M_S > self.reserve_m_s + 1e-6


class PerigeeThreshold(Threshold):
    """Reboost when the perigee is below ``threshold`` [km], keeping a reserve for the disposal."""

    name = "perigee_threshold"
    grid = PERIGEE_THRESHOLDS_KM

    def actions(self, obs: FloatArray) -> NDArray[np.int64]:
        """The largest burn where the perigee is low and the tank holds more than the reserve."""
        low = observed(obs, "perigee") * HEIGHT_SCALE_M < self.threshold * 1e3
        return np.where(low & self._spare(obs), largest_burn(self.task), 0).astype(np.int64)


class LifeThreshold(Threshold):
    """Reboost when the predicted lifetime is below ``threshold`` x the mission's time left, keeping a reserve."""

    name = "life_threshold"
    grid = LIFE_SHARES

    def actions(self, obs: FloatArray) -> NDArray[np.int64]:
        """The largest burn where the predicted life is short of the time left and the tank holds the reserve."""
        life_days = solar_task.predicted_life_days(observed(obs, "predicted_lifetime"))
        left_days = (1.0 - observed(obs, "mission_clock")) * self.task.mission_days
        short = life_days < self.threshold * left_days
        return np.where(short & self._spare(obs) & (left_days > 0.0), largest_burn(self.task), 0).astype(np.int64)


class GreedyConstant(Never):
    """The greedy look-ahead with the observed activity held constant (last month's drag, at the perigee).

    For each burn: burn now, never again; the days in orbit to the mission's end at the last
    month's multiplier, less the burn's cost, less the disposal this orbit would then need at the
    same multiplier (or the penalty if the tank could not pay it).
    """

    name = "greedy_constant"

    def actions(self, obs: FloatArray) -> NDArray[np.int64]:
        """The burn with the best look-ahead value."""
        task = self.task
        state = solar_task.decode(task, obs)
        left_days = (task.config.horizon_steps - state.steps) * task.mission.block_days
        cost = task.config.propellant_cost_per_m_s
        best = np.full(state.size, -np.inf)
        choice = np.zeros(state.size, dtype=np.int64)
        for index, size in enumerate(task.config.burn_sizes_m_s):
            trial = state.copy()
            made = task_model.burn(task, trial, np.full(trial.size, size))
            rate_s = solar_task.drag_rate(trial) * trial.density_scale * SECONDS_PER_DAY  # W per day
            weighted = trial.period_s * trial.nu
            life = weighted / rate_s
            value = np.minimum(life, left_days) - cost * made
            up = life > left_days
            if up.any():
                end = weighted[up] - rate_s[up] * left_days[up]
                label = trial.label[up]
                _, hp, ha, _ = task.curves.move_to_weight(
                    label, trial.nu[up], weighted[up], end, trial.perigee_m[up], trial.apogee_m[up]
                )
                allowed = rate_s[up] * task.mission.disposal_days
                low, high = np.full(hp.shape, REENTRY_ALTITUDE_M), hp.copy()
                complies = end <= allowed
                for _ in range(GREEDY_BISECTIONS):
                    middle = 0.5 * (low + high)
                    ok = task.curves.locate(middle, ha).weighted_s <= allowed
                    low, high = np.where(ok, middle, low), np.where(ok, high, middle)
                need = np.where(complies, 0.0, dv_to_lower_perigee_m_s(hp, ha, low))
                able = need <= trial.dv_left_m_s[up] + 1e-9
                value[up] -= np.where(able, cost * need, task.penalty_days)
            better = value > best + 1e-9
            best = np.where(better, value, best)
            choice = np.where(better, index, choice)
        return choice


@dataclass(frozen=True)
class Flown:
    """Missions flown by one policy (arrays over the missions)."""

    returns: FloatArray
    days_in_orbit: FloatArray
    dv_m_s: FloatArray  # perigee burns and the disposal burn
    disposal_m_s: FloatArray
    complies: NDArray[np.bool_]
    reentered: NDArray[np.bool_]

    def episodes(self) -> Episodes:
        """As `orbit_env.agents.evaluate.Episodes` (its summary and paired differences)."""
        return Episodes(returns=self.returns, lifetime_days=self.days_in_orbit, dv_m_s=self.dv_m_s)


def starts(task: SolarTask, episodes: int, seed: int) -> dict[str, FloatArray]:
    """The start options of ``episodes`` missions drawn from the task's split with ``seed``."""
    return solar_task.start_options(solar_task.start(task, np.random.default_rng(seed), episodes))


def fly(
    task: SolarTask,
    options: Mapping[str, Any],
    act: Callable[[BatchState], FloatArray],
    on_step: Callable[[NDArray[np.intp], BatchState, SolarStep], None] | None = None,
) -> Flown:
    """Fly the missions of ``options`` with ``act`` (states -> burns requested [m/s]) to their ends.

    ``on_step(rows, states, result)``, if given, sees each step of the missions still flying: their
    rows, their states after the step and its result (`orbit_env.agents.solar_maps` records the flights).
    """
    state = solar_task.start(task, np.random.default_rng(0), len(options["start_day"]), options)
    return fly_from(task, state, act, on_step)


def fly_from(
    task: SolarTask,
    state: BatchState,
    act: Callable[[BatchState], FloatArray],
    on_step: Callable[[NDArray[np.intp], BatchState, SolarStep], None] | None = None,
) -> Flown:
    """`fly` from missions under way (``state``, flown on in place) instead of their starts."""
    n = state.size
    total, dv, disposal = np.zeros(n), np.zeros(n), np.zeros(n)
    complies, reentered = np.ones(n, dtype=bool), np.zeros(n, dtype=bool)
    running = np.ones(n, dtype=bool)
    while running.any():
        rows = np.flatnonzero(running)
        sub = state.take(rows)
        result = solar_task.step(task, sub, checked_burns(task, act(sub), sub.size))
        state.put(rows, sub)
        if on_step is not None:
            on_step(rows, sub, result)
        total[rows] += result.reward
        dv[rows] += result.burn_m_s + result.disposal_m_s
        disposal[rows] += result.disposal_m_s
        complies[rows] &= result.complies
        reentered[rows] |= result.terminated
        running[rows] = ~(result.terminated | result.truncated)
    return Flown(total, state.time_days.copy(), dv, disposal, complies, reentered)


def checked_burns(task: SolarTask, burns_m_s: Any, n: int) -> FloatArray:
    """The burns an ``act`` of `fly` asked for, as the environment would let them be flown, or an error.

    Each a burn [m/s] of the task's sizes (the continuous twin: from 0 to ``max_burn_m_s``); one per
    mission flying (or one for all). A plan a policy could not fly in the environment is not scored.

    Raises:
        ValueError: a burn that is not a number, negative, NaN, above the largest, or (discrete) not a size.
    """
    asked = np.asarray(burns_m_s, dtype=np.float64)
    if asked.shape not in ((), (n,)):
        raise ValueError(f"burns of shape {asked.shape} asked for {n} missions flying; allowed: one, or one a mission")
    burns = np.broadcast_to(asked, (n,))
    top = task.config.max_burn_m_s
    bad = ~np.isfinite(burns) | (burns < 0.0) | (burns > top)
    if not task.continuous:
        bad |= ~np.isin(burns, task.burn_sizes_m_s)
    if bad.any():
        allowed = f"0 to {top:g} m/s" if task.continuous else f"the burn sizes {task.config.burn_sizes_m_s} m/s"
        raise ValueError(f"a burn of {float(burns[bad][0])!r} m/s asked for; allowed: {allowed}")
    return burns


def by_observation(task: SolarTask, policy: Never) -> Callable[[BatchState], FloatArray]:
    """An observation policy as `fly`'s ``act``: it sees `orbit_env.envs.solar_task.observe`, no more."""
    return lambda state: policy.burns_m_s(solar_task.observe(task, state))


def by_model(task: SolarTask, model: Any) -> Callable[[BatchState], FloatArray]:
    """A learned model (SB3's ``predict``) as `fly`'s ``act``: deterministic actions on the observation.

    The actions become burns as the task's environment reads them (`orbit_env.envs.task.Task.requested_dvs`:
    a burn size's index, or the continuous twin's a in [-1, 1]).
    """

    def act(state: BatchState) -> FloatArray:
        actions = predicted_actions(model, solar_task.observe(task, state), task.action_space)
        return task.requested_dvs(actions, state.size)

    return act


def fly_model(
    model: Any, episodes: int, seed: int, env_kwargs: Mapping[str, Any] | None = None, env_id: str = SOLAR_ENV_ID
) -> Flown:
    """A learned model's missions: ``episodes`` starts drawn with ``seed`` from the split of ``env_kwargs``.

    ``env_kwargs`` are the environment's keywords (the training config's ``[env]`` table; default: the
    train split), so `orbit_env.agents.train.BestModelCallback` validates on the split trained on;
    ``env_id`` the solar task's id (its continuous twin's keywords added).
    """
    import gymnasium

    from orbit_env.envs.solar import solar_task_of

    task = solar_task_of(None, {**gymnasium.spec(env_id).kwargs, **(env_kwargs or {})})
    return fly(task, starts(task, episodes, seed), by_model(task, model))


def tune(task: SolarTask) -> dict[str, tuple[float, float]]:
    """The threshold and reserve of each `Threshold` rule of `SOLAR_RULES` that do best on the train split.

    Each candidate flies the same `TUNE_EPISODES` missions of the train split (seed `TUNE_SEED`),
    whatever split ``task`` is on; the rules burn their sizes, so the continuous twin's are the same.
    """
    rules = tuple(rule for rule in registered_rules() if issubclass(rule, Threshold))
    return _tune(task.config, _with_split(task.mission, "train"), rules)


def registered_rules() -> tuple[type[Never], ...]:
    """`SOLAR_RULES`, checked: each rule its own ``name``, each `Threshold` rule a ``grid`` to tune.

    Raises:
        ValueError: two rules of one name (a subclass inherits its parent's), or a threshold rule without a grid.
    """
    names = [rule.name for rule in SOLAR_RULES]
    for rule in SOLAR_RULES:
        if names.count(rule.name) > 1:
            classes = ", ".join(other.__name__ for other in SOLAR_RULES if other.name == rule.name)
            raise ValueError(f"rules {classes} share the name {rule.name!r}: give each rule in SOLAR_RULES a name")
        if issubclass(rule, Threshold) and not rule.grid:
            raise ValueError(f"{rule.__name__} is a Threshold rule without a grid: give it the thresholds to tune")
    return SOLAR_RULES


@lru_cache(maxsize=4)
def _tune(config: Any, mission: SolarMission, rules: tuple[type[Threshold], ...]) -> dict[str, tuple[float, float]]:
    train = SolarTask(config=config, mission=mission)
    options = starts(train, TUNE_EPISODES, TUNE_SEED)
    best: dict[str, tuple[float, float]] = {}
    for rule in rules:
        scores = {
            (float(x), reserve): fly(train, options, by_observation(train, rule(train, x, reserve))).returns.mean()
            for x in rule.grid
            for reserve in RESERVES_M_S
        }
        best[rule.name] = max(scores, key=lambda key: scores[key])
    return best


def _with_split(mission: SolarMission, split: str) -> SolarMission:
    return replace(mission, solar_split=split)


def hand_coded(task: SolarTask) -> dict[str, Never]:
    """The operators' rules by name, in `SOLAR_RULES`' order, the thresholds tuned on the train split (`tune`)."""
    tuned = tune(task)
    return {rule.name: _made(rule, task, tuned) for rule in registered_rules()}


def _made(rule: type[Never], task: SolarTask, tuned: Mapping[str, tuple[float, float]]) -> Never:
    if issubclass(rule, Threshold):
        return rule(task, *tuned[rule.name])
    return rule(task)


#: The operators' rules in the order of the rows (the optimum's row follows them): each row of `evaluate_solar`.
SOLAR_RULES: tuple[type[Never], ...] = (Never, AllAtOnce, PerigeeThreshold, LifeThreshold, GreedyConstant)
#: The shipped rules' names (an evaluation's own are `SolarEvaluation.rules`).
SOLAR_HAND_CODED = tuple(rule.name for rule in SOLAR_RULES)


def map_missions(
    task: SolarTask,
    options: Mapping[str, FloatArray],
    solve: Callable[[tuple[SolarTask, dict[str, float]]], Any],
    workers: int | None = None,
) -> list[Any]:
    """``solve((task, one mission's options))`` for every mission of ``options``, in order.

    In ``workers`` processes (default: the cores, at most 8; 1: in this one): one DP a
    mission is seconds of work, and its tables stay in the worker.
    """
    n = len(options["start_day"])
    jobs = [(task, {key: float(value[i]) for key, value in options.items()}) for i in range(n)]
    count = workers or min(os.cpu_count() or 1, 8)
    if count > 1 and n > 1:
        with worker_pool(count) as pool:  # stopped at once if this process is interrupted (Ctrl-C, SIGTERM)
            return list(pool.map(solve, jobs))
    return [solve(job) for job in jobs]


def _fly_dp(
    job: tuple[SolarTask, dict[str, float]], rollout: bool = False
) -> tuple[float, float, float, float, bool, bool, float]:
    """Solve one mission's DP and fly its policy, or the rollout on it (in a worker: the DP's tables stay there)."""
    from orbit_env.agents.solar_dp import SolarDP, dp_task

    task, option = job
    options = {k: np.array([v]) for k, v in option.items()}
    dp = SolarDP(dp_task(task), option["start_day"])
    flown = fly(task, options, dp.rollout_burns_m_s if rollout else dp.burns_m_s)
    start = solar_task.start(task, np.random.default_rng(0), 1, options)
    return (
        float(flown.returns[0]),
        float(flown.days_in_orbit[0]),
        float(flown.dv_m_s[0]),
        float(flown.disposal_m_s[0]),
        bool(flown.complies[0]),
        bool(flown.reentered[0]),
        float(dp.value(start)[0]),
    )


@dataclass(frozen=True)
class SolarEvaluation:
    """Every policy on the same missions, and the optimum's estimate of itself."""

    flown: dict[str, Flown]
    dp_estimate: FloatArray  # V_0 of the DP's grid at each start (the certificate's other side)
    tuned: dict[str, tuple[float, float]]
    rules: tuple[str, ...]  # the hand-coded rules' rows, in order (`SOLAR_RULES`)


def evaluate_solar(
    episodes: int,
    seed: int,
    *,
    solar_split: str = SOLAR_EVAL_SPLIT,
    disposal_years: float = DISPOSAL_YEARS,
    include_dp: bool = True,
    dp_rollout: bool = False,
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
    learned: Mapping[str, Any] | None = None,
    continuous: bool = False,
) -> SolarEvaluation:
    """Fly every hand-coded rule, the optimum and the ``learned`` agents on ``episodes`` missions of the split.

    The missions are drawn with ``seed``. ``learned``: row name -> a model answering SB3's ``predict``
    (e.g. ``{"ppo": model}``), flown with deterministic actions after the optimum's row. ``dp_rollout``:
    the optimum's row is the rollout policy on each mission's DP (`SolarDP.rollout_burns_m_s`).
    ``continuous``: the continuous twin (``OrbitRaisingSolarContinuous-v0``): the learned agents act in
    its Box, the DP on a finer grid of burns (`orbit_env.agents.solar_dp.dp_task`); the rules are the same.
    """
    check_int(episodes, "episodes", low=1)
    check_int(seed, "seed", low=0)
    mission = SolarMission(solar_split=solar_split, disposal_years=disposal_years)
    task = SolarTask(mission=mission, continuous=continuous)
    names = {rule.name for rule in registered_rules()} | {"dp"}
    clash = sorted(names & set(learned or {}))
    if clash:
        raise ValueError(f"learned agent {clash[0]!r} has the name of a row of the evaluation; allowed: another name")
    options = starts(task, episodes, seed)
    say = progress or (lambda _: None)
    say("tuning the thresholds on the train split")
    policies = hand_coded(task)
    flown = {}
    for name, policy in policies.items():
        say(name)
        flown[name] = fly(task, options, by_observation(task, policy))
    estimate = np.full(episodes, np.nan)
    if include_dp:
        say(f"dp ({episodes} missions, one DP each)")
        rows = map_missions(task, options, partial(_fly_dp, rollout=dp_rollout), workers)
        columns = list(zip(*rows, strict=True))
        flown["dp"] = Flown(
            np.array(columns[0]),
            np.array(columns[1]),
            np.array(columns[2]),
            np.array(columns[3]),
            np.array(columns[4]),
            np.array(columns[5]),
        )
        estimate = np.array(columns[6])
    for name, model in (learned or {}).items():
        say(name)
        flown[name] = fly(task, options, by_model(task, model))
    return SolarEvaluation(flown, estimate, dict(tune(task)), tuple(policies))


def solar_report(evaluation: SolarEvaluation) -> dict[str, Any]:
    """What the solar evaluation adds to the table: the rule's shares per policy, the tuning, the certificate."""
    report: dict[str, Any] = {
        "policies": {
            name: {
                "disposal_share": float((flown.disposal_m_s > 0.0).mean()),
                "noncompliant_share": float((~flown.complies).mean()),
                "reentered_share": float(flown.reentered.mean()),
                "mean_disposal_m_s": float(flown.disposal_m_s.mean()),
            }
            for name, flown in evaluation.flown.items()
        },
        "tuned": {name: list(values) for name, values in evaluation.tuned.items()},
    }
    if "dp" in evaluation.flown:
        dp = evaluation.flown["dp"].returns
        gap = evaluation.dp_estimate - dp
        rules = np.max([evaluation.flown[name].returns for name in evaluation.rules], axis=0)
        report["rule_binds_share"] = report["policies"]["dp"]["disposal_share"]
        report["certificate"] = {
            "mean_gap_days": float(gap.mean()),
            "max_gap_days": float(gap.max()),
            "beaten_by_a_rule": int(np.sum(rules > dp + 1e-6)),
            "largest_rule_lead_days": float(np.max(rules - dp)),
        }
    return report
