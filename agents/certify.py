"""How far below the true optimum is the DP? A search for plans that beat it (``orbit-env evaluate --certify``).

The DP (`orbit_env.agents.dp`) is the yardstick of every capture, but it is solved
on a grid, so its policy can be beaten. This check searches, start by start, for an
action sequence that earns more than the DP policy in the environment itself, and
reports the gap it finds: a lower bound on the DP policy's distance to the optimum
(no search proves there is no better plan; a found gap is real).

For each of ``episodes`` seeded start orbits (those of ``orbit-env evaluate``):

1. the DP policy plays the episode; its return is the reference and its actions the
   first plan (certifying a policy of one's own, ``policy=``: that policy's return is the
   reference, and the first plan is its actions or the DP policy's, whichever earns more,
   so that the gap found is at least what the DP already shows);
2. every open-loop plan of burns on the first `EARLY_STEPS` steps (all
   combinations of `EARLY_BURNS`), then coasting;
3. hill climbing from the best plan so far: ``rounds`` rounds of ``perturbations``
   random changes each (move a burn by up to `MAX_SHIFT` steps, resize it, split
   it over two steps, add one in the first `ADD_WINDOW` steps, or drop one),
   keeping a change that earns more.

Every plan is scored in ``gymnasium.make_vec`` of the environment (the task model, no
shortcut), all starts and candidates at once; the plans that beat the DP are replayed
in ``gymnasium.make``, one environment each, and the replayed returns are the ones
reported. The gap of a start is max(0, best plan - DP policy) in days of return.

On ``OrbitRaisingSolar-v0`` the DP is each mission's own (it knows the mission's Sun,
`orbit_env.agents.solar_dp`), solved per mission in worker processes; the burns it asks
for are its plan, replayed first in the vector env (its return must come back: the
replay's difference is reported), and the search runs from there on the missions of
``orbit-env evaluate --env OrbitRaisingSolar-v0`` (same seed, split and rule).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any, NamedTuple

import gymnasium
import numpy as np
from numpy.typing import NDArray

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents.evaluate import EVAL_SEED, Predictor, check_env_id, dp_policy, predicted_actions, task_of
from orbit_env.agents.evaluate import policy_name as evaluated_name  # the Certificate's policy_name is its text
from orbit_env.checks import check_int
from orbit_env.envs import SOLAR_ENV_IDS, SOLAR_EVAL_SPLIT

FloatArray = NDArray[np.float64]

#: Steps at the start over which every combination of `EARLY_BURNS` is tried.
EARLY_STEPS = 3
#: Burns tried in those steps [m/s] (the discrete variants use their own burn sizes).
EARLY_BURNS = (0.0, 10.0, 20.0, 30.0, 50.0, 100.0)
#: Largest move of a burn in time by one perturbation [steps].
MAX_SHIFT = 10
#: A perturbation adds a burn at one of the first this many steps.
ADD_WINDOW = 60
#: Gains below this [days] are ties: the DP's values are stored in steps of 0.01 day.
TIE_DAYS = 0.01


@dataclass(frozen=True)
class Certificate:
    """What the search found: per start, the DP policy's return and the best plan's (replayed)."""

    env_id: str
    seed: int
    dp_returns: FloatArray
    best_returns: FloatArray
    perigee_km: FloatArray
    apogee_km: FloatArray
    wall_s: float
    plans_scored: int
    replay_max_error: float = field(default=0.0)
    start_dates: tuple[str, ...] = ()  # the solar task's missions' first days
    policy_name: str = "DP policy"  # what was certified: the DP's, or a caller's ("policy" and its class name)

    @property
    def gaps(self) -> FloatArray:
        """max(0, best plan - DP policy) per start [days]."""
        return np.maximum(self.best_returns - self.dp_returns, 0.0)

    def summary(self) -> dict[str, Any]:
        """Mean and worst gap, where the worst is, and how many starts the DP lost by more than 0.1 day."""
        gaps = self.gaps
        worst = int(np.argmax(gaps))
        return {
            "env": self.env_id,
            "seed": self.seed,
            "episodes": int(gaps.size),
            "mean_gap_days": float(gaps.mean()),
            "worst_gap_days": float(gaps[worst]),
            "worst_episode": worst,
            "worst_start_km": [float(self.perigee_km[worst]), float(self.apogee_km[worst])],
            **({"worst_start_date": self.start_dates[worst]} if self.start_dates else {}),
            "beaten_above_0.1_day": int(np.sum(gaps > 0.1)),
            "beaten_at_all": int(np.sum(gaps > TIE_DAYS)),
            "policy": self.policy_name,
            "dp_mean_return": float(self.dp_returns.mean()),
            "plans_scored": int(self.plans_scored),
            "replay_max_error_days": float(self.replay_max_error),
            "wall_s": float(self.wall_s),
        }


class _Plans:
    """Scoring action plans (one row per start and candidate) in the vector env.

    ``options`` are the starts' reset options, arrays over the starts (the known-density
    envs' heights, or the solar task's `orbit_env.envs.solar_task.start_options`).
    """

    def __init__(self, env_id: str, options: dict[str, FloatArray], env_kwargs: dict[str, Any] | None = None) -> None:
        self.env_id = env_id
        self.env_kwargs = dict(env_kwargs or {})
        probe = gymnasium.make(env_id, **self.env_kwargs)
        task = probe.unwrapped.task
        probe.close()
        self.continuous = task.continuous
        self.horizon = task.config.horizon_steps
        self.max_burn = task.config.max_burn_m_s
        self.sizes = np.asarray(task.config.burn_sizes_m_s, dtype=np.float64)
        self.options = options
        self.scored = 0

    def actions(self, burns_m_s: FloatArray) -> Any:
        """Env actions of burns [m/s] (discrete: the nearest size's index)."""
        if self.continuous:
            return (np.clip(burns_m_s / self.max_burn, 0.0, 1.0)[..., None]).astype(np.float32)
        return np.abs(burns_m_s[..., None] - self.sizes).argmin(axis=-1).astype(np.int64)

    def score(self, starts: NDArray[np.intp], burns_m_s: FloatArray, policy: Predictor | None = None) -> Any:
        """Returns of the plans (rows of ``burns_m_s``, shape (k, horizon)) from ``starts``.

        With ``policy`` the plans are ignored and the policy acts; then also its burns.
        """
        k = starts.size
        env = gymnasium.make_vec(self.env_id, num_envs=k, **self.env_kwargs)
        obs, _ = env.reset(seed=0, options={key: value[starts] for key, value in self.options.items()})
        returns = np.zeros(k)
        made = np.zeros((k, self.horizon))
        running = np.ones(k, dtype=bool)
        for t in range(self.horizon):
            if policy is None:
                action = self.actions(burns_m_s[:, t])
            else:
                # The policy acts on the episodes still scored; the restarted ones coast (a DP
                # then reads one stage of its values a step, see orbit_env.agents.stage_values).
                action = self.actions(np.zeros(k))
                rows = np.flatnonzero(running)
                action[rows] = predicted_actions(policy, obs[rows], env.single_action_space)  # checked as evaluate's
            obs, reward, terminated, truncated, info = env.step(action)
            returns += np.where(running, reward, 0.0)
            made[:, t] = np.where(running, info["burn_m_s"], 0.0)
            running &= ~(terminated | truncated)
            if not running.any():
                break
        env.close()
        self.scored += k
        return (returns, made) if policy is not None else returns

    def replay(self, start: int, burns_m_s: FloatArray) -> float:
        """The plan's return in ``gymnasium.make`` (one environment)."""
        env = gymnasium.make(self.env_id, **self.env_kwargs)
        env.reset(seed=0, options={key: float(value[start]) for key, value in self.options.items()})
        total = 0.0
        for t in range(self.horizon):
            action = self.actions(burns_m_s[t : t + 1])[0]
            _, reward, terminated, truncated, _ = env.step(action if self.continuous else int(action))
            total += float(reward)
            if terminated or truncated:
                break
        env.close()
        return total


def _early_plans(plans: _Plans) -> FloatArray:
    """Every combination of early burns on the first `EARLY_STEPS` steps, then coasting: (m, horizon)."""
    burns = plans.sizes if not plans.continuous else np.unique(np.minimum(EARLY_BURNS, plans.max_burn))
    grids = np.meshgrid(*([burns] * EARLY_STEPS), indexing="ij")
    early = np.stack([g.ravel() for g in grids], axis=1)
    out = np.zeros((early.shape[0], plans.horizon))
    out[:, :EARLY_STEPS] = early
    return out


def _perturb(plan: FloatArray, rng: np.random.Generator, plans: _Plans) -> FloatArray:
    """One random change of a plan (see the module)."""
    new = plan.copy()
    burns = np.flatnonzero(new > 0.0)
    kind = rng.integers(5) if burns.size else 3
    step = plans.max_burn / 10.0 if plans.continuous else None
    if kind == 0:  # move a burn
        t = rng.choice(burns)
        to = int(np.clip(t + rng.integers(-MAX_SHIFT, MAX_SHIFT + 1), 0, plans.horizon - 1))
        new[t], new[to] = new[to], new[t]
    elif kind == 1:  # resize a burn
        t = rng.choice(burns)
        if plans.continuous:
            new[t] = np.clip(new[t] + rng.normal(0.0, step), 0.0, plans.max_burn)
        else:
            i = int(np.abs(plans.sizes - new[t]).argmin()) + rng.choice([-1, 1])
            new[t] = plans.sizes[int(np.clip(i, 0, plans.sizes.size - 1))]
    elif kind == 2:  # split a burn over it and the next step
        t = rng.choice(burns)
        if t + 1 < plans.horizon:
            if plans.continuous:
                part = new[t] * rng.uniform(0.2, 0.8)
            else:
                smaller = plans.sizes[(plans.sizes > 0) & (plans.sizes < new[t])]
                part = new[t] - (rng.choice(smaller) if smaller.size else 0.0)
            new[t] -= part
            new[t + 1] += part
            if not plans.continuous:
                new[t + 1] = plans.sizes[np.abs(plans.sizes - new[t + 1]).argmin()]
    elif kind == 3:  # add a burn early
        t = rng.integers(min(ADD_WINDOW, plans.horizon))
        positive = plans.sizes[plans.sizes > 0]
        new[t] = rng.uniform(0.0, plans.max_burn) if plans.continuous else rng.choice(positive)
    else:  # drop a burn
        new[rng.choice(burns)] = 0.0
    return new


class _Optimum(NamedTuple):
    """The starts (as plans are scored from them) and the DP policy on them."""

    plans: _Plans
    returns: FloatArray
    burns_m_s: FloatArray  # (starts, horizon): its plan
    start_dates: tuple[str, ...] = ()  # the solar task's missions' first days
    # Where the search starts if not from the plan above (a policy's certificate: the DP policy's where it is better).
    first_plans: FloatArray | None = None
    first_returns: FloatArray | None = None


def _start_heights(plans: _Plans) -> tuple[FloatArray, FloatArray]:
    """The starts' perigee and apogee heights [km]: the options', or the env's task state after its reset."""
    if "perigee_km" in plans.options:
        return plans.options["perigee_km"], plans.options["apogee_km"]
    env = gymnasium.make_vec(plans.env_id, num_envs=len(next(iter(plans.options.values()))), **plans.env_kwargs)
    env.reset(seed=0, options=plans.options)
    state = env.unwrapped.task_state
    heights = state.perigee_m / 1e3, state.apogee_m / 1e3
    env.close()
    return heights


def _known_density_optimum(
    env_id: str, episodes: int, seed: int, policy: Predictor | None, dp_lookahead: int, dp_rollout: bool
) -> _Optimum:
    """The seeded starts' plans, and the DP policy's returns and burns on them (a known-density env)."""
    check_env_id(env_id)
    base = task_of(env_id)
    if base.density.scale_range[0] != base.density.scale_range[1] or base.density.varies:
        raise ValueError(f"{env_id}: the certificate needs a known, constant density (the DP's task)")
    env = gymnasium.make_vec(env_id, num_envs=episodes)
    env.reset(seed=seed)
    heights = {"perigee_km": env.unwrapped.state["perigee_m"] / 1e3, "apogee_km": env.unwrapped.state["apogee_m"] / 1e3}
    env.close()
    plans = _Plans(env_id, heights)
    zero = np.zeros((episodes, plans.horizon))
    returns, burns = plans.score(np.arange(episodes), zero, policy or dp_policy(env_id, dp_lookahead, dp_rollout))
    if policy is not None:  # the search starts from the better of the policy's plan and the DP policy's
        _, dp_burns = plans.score(np.arange(episodes), zero, dp_policy(env_id))
        # The DP policy's burns as a plan, scored as the search scores plans (a burn the tank cut short is
        # asked again as the nearest size: its replay's return, not the policy's own).
        dp_returns = plans.score(np.arange(episodes), dp_burns)
        better = dp_returns > returns
        first = np.where(better[:, None], dp_burns, burns)
        return _Optimum(plans, returns, burns, first_plans=first, first_returns=np.where(better, dp_returns, returns))
    return _Optimum(plans, returns, burns)


def _solar_plan(job: tuple[Any, dict[str, float]], rollout: bool = False) -> tuple[float, list[float]]:
    """One mission's DP solved and flown (in a worker): its return and the burns it asked for, step by step.

    ``rollout``: the rollout policy on the DP flies (`SolarDP.rollout_burns_m_s`).
    """
    from orbit_env.agents.solar import fly
    from orbit_env.agents.solar_dp import SolarDP, dp_task

    task, option = job
    dp = SolarDP(dp_task(task), option["start_day"])
    asked: list[float] = []
    policy = dp.rollout_burns_m_s if rollout else dp.burns_m_s

    def act(state: Any) -> FloatArray:
        burn = policy(state)
        asked.append(float(burn[0]))
        return burn

    flown = fly(task, {key: np.array([value]) for key, value in option.items()}, act)
    return float(flown.returns[0]), asked


def _solar_optimum(
    env_id: str,
    episodes: int,
    seed: int,
    env_kwargs: dict[str, Any],
    workers: int | None,
    say: Callable[[str], None],
    rollout: bool = False,
) -> _Optimum:
    """The solar task's seeded missions, and each one's DP (`orbit_env.agents.solar_dp.SolarDP`) flown.

    The DP acts on the task's state (it knows the Sun's future); the burns it asks for
    are recorded as its plan, which the search then replays and perturbs in the env. The
    DPs are solved in ``workers`` processes (default: the cores, at most 8), as ``evaluate`` does.
    """
    from orbit_env.agents.solar import map_missions, starts
    from orbit_env.envs import solar_task

    probe = gymnasium.make(env_id, **env_kwargs)
    task = probe.unwrapped.task
    probe.close()
    options = starts(task, episodes, seed)
    plans = _Plans(env_id, options, env_kwargs)
    say(f"dp: {episodes} missions, one DP each")
    solved = map_missions(task, options, partial(_solar_plan, rollout=rollout), workers)
    returns, burns = np.zeros(episodes), np.zeros((episodes, plans.horizon))
    for i, (value, asked) in enumerate(solved):
        returns[i] = value
        burns[i, : len(asked)] = asked
    dates = tuple(solar_task.date_of(task, float(day)) for day in options["start_day"])
    return _Optimum(plans, returns, burns, dates)


def certify(
    env_id: str = "OrbitRaising-v0",
    episodes: int = 1000,
    seed: int = EVAL_SEED,
    *,
    rounds: int = 8,
    perturbations: int = 24,
    policy: Predictor | None = None,
    dp_lookahead: int = 1,
    dp_rollout: bool = False,
    env_kwargs: dict[str, Any] | None = None,
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> Certificate:
    """Search for plans that beat the DP policy on ``episodes`` seeded starts (see the module).

    Args:
        env_id: A known-density environment (``OrbitRaising-v0``, ``OrbitRaisingContinuous-v0``),
            or ``OrbitRaisingSolar-v0`` (each mission's DP that knows its Sun).
        episodes: Start orbits, those of ``orbit-env evaluate`` with the same seed.
        seed: Seed of the starts.
        rounds: Rounds of hill climbing.
        perturbations: Random changes tried per start and round.
        policy: The policy to certify (default: the env's DP policy; known-density envs only, the solar
            task's certificate is its DP's).
        dp_lookahead: The DP policy's ``lookahead`` (`orbit_env.agents.dp.DPPolicy`).
        dp_rollout: Certify the rollout policy on the DP (`orbit_env.agents.evaluate.dp_policy`).
        env_kwargs: The solar env's keywords (``solar_split``, default ``test`` as ``evaluate``'s; ``disposal_years``).
        workers: Processes solving the solar task's DPs (default: the cores, at most 8).
        progress: Called with a line of text as the search goes.

    Raises:
        ValueError: an unknown env, one whose density is not known (its optimum is the
            oracle's), counts below 1, or a negative seed.
    """
    if episodes < 1 or rounds < 0 or perturbations < 1:
        raise ValueError("episodes and perturbations must be >= 1, rounds >= 0")
    check_int(seed, "seed", low=0)
    if env_id in SOLAR_ENV_IDS and policy is not None:
        raise ValueError(
            f"{env_id}: the certificate searches plans against each mission's DP policy only; score your policy "
            "with orbit_env.agents.solar.evaluate_solar (learned={...}) against that DP"
        )
    if policy is not None and (dp_rollout or dp_lookahead != 1):
        given = "dp_rollout" if dp_rollout else f"dp_lookahead={dp_lookahead}"
        raise ValueError(f"{given} chooses the DP policy to certify; with policy= the policy given is certified")
    say = progress or (lambda text: None)
    start_time = time.perf_counter()
    say("dp (solving and playing)")
    if env_id in SOLAR_ENV_IDS:
        solar = {"solar_split": SOLAR_EVAL_SPLIT, **(env_kwargs or {})}
        optimum = _solar_optimum(env_id, episodes, seed, solar, workers, say, rollout=dp_rollout)
    else:
        optimum = _known_density_optimum(env_id, episodes, seed, policy, dp_lookahead, dp_rollout)
    plans, dp_returns, dp_burns = optimum.plans, optimum.returns, optimum.burns_m_s
    everyone = np.arange(episodes)
    replay_error = 0.0
    if env_id in SOLAR_ENV_IDS:  # the burns the DP asked for, as an open-loop plan in the env, give its return back
        replay_error = float(np.max(np.abs(plans.score(everyone, dp_burns) - dp_returns)))
    if optimum.first_plans is None:
        best, best_returns = dp_burns.copy(), dp_returns.copy()
    else:
        best, best_returns = optimum.first_plans.copy(), optimum.first_returns.copy()
    early = _early_plans(plans)
    say(f"{early.shape[0]} early plans per start")
    chunk = max(1, 65536 // early.shape[0])
    for lo in range(0, episodes, chunk):
        starts = everyone[lo : lo + chunk]
        returns = plans.score(np.repeat(starts, early.shape[0]), np.tile(early, (starts.size, 1)))
        returns = returns.reshape(starts.size, early.shape[0])
        top = returns.argmax(axis=1)
        better = returns[np.arange(starts.size), top] > best_returns[starts]
        best[starts[better]] = early[top[better]]
        best_returns[starts[better]] = returns[np.arange(starts.size), top][better]
    rng = np.random.default_rng(seed)
    for r in range(rounds):
        candidates = np.stack([_perturb(best[i], rng, plans) for i in everyone for _ in range(perturbations)])
        returns = plans.score(np.repeat(everyone, perturbations), candidates).reshape(episodes, perturbations)
        top = returns.argmax(axis=1)
        improved = returns[everyone, top] > best_returns
        rows = everyone * perturbations + top
        best[improved] = candidates[rows[improved]]
        best_returns[improved] = returns[everyone, top][improved]
        gap = np.maximum(best_returns - dp_returns, 0.0)
        say(f"round {r + 1}/{rounds}: mean gap {gap.mean():.3f} day, worst {gap.max():.3f}")
    # The plans that beat the DP, replayed one by one in gymnasium.make: the returns reported.
    for i in np.flatnonzero(best_returns - dp_returns > TIE_DAYS):
        replayed = plans.replay(int(i), best[i])
        replay_error = max(replay_error, abs(replayed - best_returns[i]))
        best_returns[i] = replayed
    heights = _start_heights(plans)
    return Certificate(
        env_id=env_id,
        seed=seed,
        dp_returns=dp_returns,
        best_returns=best_returns,
        perigee_km=heights[0],
        apogee_km=heights[1],
        wall_s=time.perf_counter() - start_time,
        plans_scored=plans.scored,
        replay_max_error=replay_error,
        start_dates=optimum.start_dates,
        policy_name="DP policy" if policy is None else f"policy {evaluated_name(policy)}",
    )


def format_certificate(summary: dict[str, Any]) -> str:
    """The certificate as text for people."""
    policy = summary.get("policy", "DP policy")
    replayed = "the winners in gymnasium.make" + (
        "; the solar DP's own in the vector env" if summary["env"] in SOLAR_ENV_IDS else ""
    )
    return "\n".join(
        [
            f"{summary['env']}: a search for plans that beat the {policy} on {summary['episodes']} starts "
            f"(seed {summary['seed']}), {summary['plans_scored']:,} plans scored in {summary['wall_s']:.0f} s",
            f"{policy}'s mean return {summary['dp_mean_return']:.3f} days",
            f"gap found (best plan - {policy}): mean {summary['mean_gap_days']:.3f} day, "
            + (
                f"worst {summary['worst_gap_days']:.3f} day (episode {summary['worst_episode']}, "
                f"{summary['worst_start_km'][0]:.2f} x {summary['worst_start_km'][1]:.2f} km"
                + (f", from {summary['worst_start_date']})" if "worst_start_date" in summary else ")")
                if summary["worst_gap_days"] > TIE_DAYS
                else "on no start a better plan"
            ),
            f"starts where the {'DP' if policy == 'DP policy' else policy} was beaten: {summary['beaten_at_all']} "
            f"by more than {TIE_DAYS} day, "
            f"{summary['beaten_above_0.1_day']} by more than 0.1 day",
            f"plans replayed ({replayed}): largest difference {summary['replay_max_error_days']:.1e} day",
        ]
    )
