"""Score every policy on the same seeded episodes (``orbit-env evaluate``).

The episodes are the first episode of each sub-environment of one seeded vector
environment: the start orbits (and, in ``OrbitRaisingUncertain-v0``, the hidden
density) are drawn at reset before any action, so every policy meets the same ones.
The seeds differ from training's (``agents/ppo.toml`` trains with seed 0).
"""

from __future__ import annotations

import csv
import dataclasses
import inspect
import math
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import gymnasium
import numpy as np
from numpy.typing import NDArray

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents import EVAL_EPISODES, EVAL_SEED
from orbit_env.agents.policies import HAND_CODED
from orbit_env.checks import check_int
from orbit_env.envs import ENV_IDS, SOLAR_ENV_IDS
from orbit_env.optional import TRAIN_EXTRA

FloatArray = NDArray[np.float64]

#: Episodes whose returns differ by less than this [days] count as ties in the paired comparison.
TIE_DAYS = 0.01
#: The Stable-Baselines3 algorithms ``orbit-env evaluate --model`` loads.
ALGORITHMS = ("ppo", "a2c", "dqn", "sac", "td3")


def policy_order() -> tuple[str, ...]:
    """The order of the policies in tables and JSON: `HAND_CODED`'s, then the DP, then `ALGORITHMS`.

    Read from those declarations when called, so a policy added to `HAND_CODED` is scored
    and listed with no second list to update.
    """
    return (*HAND_CODED, "dp", *ALGORITHMS)


class Predictor(Protocol):
    """Stable-Baselines3's prediction protocol."""

    def predict(
        self, observation: Any, state: Any = None, episode_start: Any = None, deterministic: bool = True
    ) -> tuple[Any, Any]:
        """Actions for a batch of observations."""
        ...


@dataclass(frozen=True)
class Episodes:
    """Per-episode results of one policy (arrays of length ``episodes``)."""

    returns: FloatArray
    lifetime_days: FloatArray
    dv_m_s: FloatArray

    def summary(self) -> dict[str, float]:
        """Mean and spread, with the public JSON keys (``capture`` is added by `summarize`)."""
        return {
            "mean_return": float(self.returns.mean()),
            "std_return": float(self.returns.std()),
            "mean_lifetime_days": float(self.lifetime_days.mean()),
            "mean_dv_m_s": float(self.dv_m_s.mean()),
        }


def check_env_id(env_id: str) -> None:
    """ValueError unless ``env_id`` is a known-density environment (the solar task has an evaluation of its own)."""
    if env_id in SOLAR_ENV_IDS:
        raise ValueError(
            f"{env_id} is scored by orbit_env.agents.solar.evaluate_solar (its missions, a DP each); "
            f"here: {', '.join(ENV_IDS)}"
        )
    if env_id not in ENV_IDS:
        raise ValueError(f"unknown environment {env_id!r}; allowed: {', '.join((*ENV_IDS, *SOLAR_ENV_IDS))}")


def predicted_actions(policy: Any, observations: Any, space: Any) -> NDArray[Any]:
    """``policy.predict``'s deterministic actions for a batch of observations, checked against ``space``.

    ``space`` is one environment's action space. A discrete action must be an integer of its range (the
    environment refuses floats, 2.0 too) and a Box action finite, one row per observation: an action the
    environment itself would refuse is an error naming the policy, not an action quietly rounded or wrapped
    (2.7 was the 30 m/s burn, -1 the largest).
    """
    rows = len(observations)
    name = policy_name(policy)
    if not hasattr(policy, "predict") and callable(policy):  # a plain function: observations -> actions
        returned = (policy(observations), None)
        if isinstance(returned[0], tuple):
            raise ValueError(
                f"{name} returned a tuple: a plain function returns the actions alone (to score a policy with "
                "predict, pass the policy, not its predict)"
            )
    else:
        _check_predict(policy, name, observations)
        returned = policy.predict(observations, deterministic=True)
        if not (isinstance(returned, tuple) and len(returned) == 2):
            raise ValueError(f"{name}.predict must return (actions, state), as Stable-Baselines3's does")
        if returned[1] is not None:
            raise ValueError(
                f"{name}.predict returned a state ({type(returned[1]).__name__}): the episodes are scored with "
                "memoryless calls, predict(observations, deterministic=True), its state never passed back; every "
                "observation holds the clock, the tank and the orbit, so decide from it (return the state given, None)"
            )
    dtype = np.asarray(returned[0]).dtype
    kind = dtype.kind
    if kind == "b":
        raise ValueError(f"{name}.predict returned booleans as actions; allowed: numbers of the action space")
    if kind in "OSUV":
        raise ValueError(f"{name}.predict returned actions that are not numbers ({dtype}): {returned[0]!r:.80}")
    try:
        actions = np.asarray(returned[0], dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name}.predict returned actions that are not numbers: {returned[0]!r:.80}") from None
    shape = (rows, *space.shape)
    if actions.shape != shape:
        raise ValueError(f"{name}.predict returned actions of shape {actions.shape}, not {shape} ({rows} observations)")
    if not np.all(np.isfinite(actions)):
        raise ValueError(f"{name}.predict returned an action that is not finite: {actions[~np.isfinite(actions)][0]}")
    if actions.size == 0:  # no observation, no action
        return actions.astype(np.int64 if isinstance(space, gymnasium.spaces.Discrete) else space.dtype)
    if isinstance(space, gymnasium.spaces.Discrete):
        allowed = f"integers in [{space.start}, {space.start + space.n - 1}]"
        if kind not in "iu":
            raise ValueError(
                f"{name}.predict returned {dtype} actions for a discrete space ({float(actions.flat[0])!r} first); "
                f"allowed: {allowed} (the environment refuses a float action, 2.0 too)"
            )
        inside = (actions >= space.start) & (actions < space.start + space.n)
        if not inside.all():
            raise ValueError(f"{name}.predict returned action {actions[~inside][0]:g}; allowed: {allowed}")
        return actions.astype(np.int64)
    if np.dtype(space.dtype).kind == "f":  # 1e300 is finite, not in float32
        beyond = np.abs(actions) > np.finfo(space.dtype).max
        if beyond.any():
            raise ValueError(f"{name}.predict returned action {actions[beyond][0]:g}, beyond {space.dtype}")
    return actions.astype(space.dtype)


def policy_name(policy: Any) -> str:
    """How messages name a policy: a plain function by its name, an object with ``predict`` by its class."""
    if not hasattr(policy, "predict") and callable(policy):
        return getattr(policy, "__name__", type(policy).__name__)
    return type(policy).__name__


def load_policy(spec: str) -> tuple[str, Any]:
    """A policy of one's own named ``FILE.py:NAME`` or ``MODULE:NAME``: (its row's name, the policy).

    NAME is an object with Stable-Baselines3's ``predict``, a function ``observations -> actions``,
    or a class of either made with no arguments (made here). The row is named NAME.

    Raises:
        ValueError: a spec without its two parts, a file or module that is not there, no NAME in it, a
            class that takes arguments, or an object that neither predicts nor is called.
    """
    import importlib
    import importlib.util
    import sys

    where, colon, attribute = spec.rpartition(":")
    if not colon or not where or not attribute.isidentifier():
        raise ValueError(f"--policy {spec}: give FILE.py:NAME or MODULE:NAME (NAME a policy in it)")
    if where.endswith(".py"):
        path = Path(where)
        if not path.is_file():
            raise ValueError(f"--policy {spec}: no file {where}")
        module_spec = importlib.util.spec_from_file_location(f"_orbit_env_policy_{path.stem}", path)
        assert module_spec is not None and module_spec.loader is not None
        module = importlib.util.module_from_spec(module_spec)
        sys.modules[module_spec.name] = module  # (a dataclass in the file looks its module up)
        module_spec.loader.exec_module(module)
    else:
        try:
            module = importlib.import_module(where)
        except ModuleNotFoundError as error:
            raise ValueError(f"--policy {spec}: no module {error.name} (a file: FILE.py:NAME)") from None
    if not hasattr(module, attribute):
        raise ValueError(f"--policy {spec}: {where} has no {attribute}")
    policy = getattr(module, attribute)
    if isinstance(policy, type):
        try:
            policy = policy()
        except TypeError as error:
            why = f"the class {attribute} must be made with no arguments ({error})"
            raise ValueError(f"--policy {spec}: {why}") from None
    if not hasattr(policy, "predict") and not callable(policy):
        raise ValueError(f"--policy {spec}: {attribute} has no predict and is not a function observations -> actions")
    return attribute, policy


def _check_predict(policy: Any, name: str, observations: Any) -> None:
    """ValueError unless ``policy.predict`` takes (observations, deterministic=True), as Stable-Baselines3's does."""
    try:
        inspect.signature(policy.predict).bind(observations, deterministic=True)
    except TypeError:
        raise ValueError(
            f"{name}.predict must take predict(observation, state=None, episode_start=None, deterministic=False), "
            "as Stable-Baselines3's does (or score a plain function observations -> actions)"
        ) from None
    except ValueError:  # no signature to read (a builtin): called as it is
        pass


def run_episodes(
    env_id: str,
    policy: Predictor,
    episodes: int = EVAL_EPISODES,
    seed: int = EVAL_SEED,
    *,
    env_kwargs: Mapping[str, Any] | None = None,
) -> Episodes:
    """Play one episode per sub-environment of a seeded vector env with ``policy``.

    ``seed``: an integer >= 0, as Gymnasium seeds. ``env_kwargs``: the environment's keywords
    (``horizon_steps=...``, see `orbit_env.envs.OrbitRaisingEnv`).
    """
    check_env_id(env_id)
    if episodes < 1:
        raise ValueError(f"episodes must be >= 1, got {episodes}")
    check_int(seed, "seed", low=0)
    env = gymnasium.make_vec(env_id, num_envs=episodes, **dict(env_kwargs or {}))
    obs, _ = env.reset(seed=seed)
    cost = env.unwrapped.config.propellant_cost_per_m_s
    returns = np.zeros(episodes)
    days = np.zeros(episodes)
    dv = np.zeros(episodes)
    running = np.ones(episodes, dtype=bool)
    actions = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    oracle = policy if isinstance(policy, OracleDP) else None  # reads the hidden state it is told; no one else
    first = True
    try:
        while running.any():
            # Only the first episode of each satellite is scored: the policy acts on the
            # running ones (the restarted ones coast), so a DP reads only the current stage.
            rows = np.flatnonzero(running)
            if oracle is not None:
                oracle.bind(env, rows)
            actions[...] = 0
            actions[rows] = predicted_actions(policy, obs[rows], env.single_action_space)
            if first:  # the same observations asked again: a policy that answers otherwise is not reproducible
                first = False
                if not np.array_equal(predicted_actions(policy, obs[rows], env.single_action_space), actions[rows]):
                    warnings.warn(
                        f"{policy_name(policy)} acts otherwise on the same observations (deterministic=True asked): "
                        "its scores change from run to run, and a paired difference against it is not reproducible",
                        UserWarning,
                        stacklevel=2,
                    )
            obs, reward, terminated, truncated, info = env.step(actions)
            burn = np.asarray(info["burn_m_s"], dtype=np.float64)
            returns += np.where(running, reward, 0.0)
            days += np.where(running, reward + cost * burn, 0.0)
            dv += np.where(running, burn, 0.0)
            running &= ~(terminated | truncated)
    finally:
        if oracle is not None:
            oracle.bind(None)  # no stale episodes to read afterwards
        env.close()
    return Episodes(returns=returns, lifetime_days=days, dv_m_s=dv)


def capture(mean_return: float, never_return: float | None, dp_return: float | None) -> float | None:
    """(R - R_never) / (R_dp - R_never): the share of the optimum's improvement over never burning.

    None without both references, or where never burning is optimal (no improvement to share).
    """
    if never_return is None or dp_return is None or abs(dp_return - never_return) < 1e-9:
        return None
    return float((mean_return - never_return) / (dp_return - never_return))


def summarize(results: Mapping[str, Episodes]) -> dict[str, dict[str, float | None]]:
    """Per-policy summary with its `capture`."""
    table: dict[str, dict[str, float | None]] = {}
    never = float(results["never"].returns.mean()) if "never" in results else None
    best = float(results["dp"].returns.mean()) if "dp" in results else None
    for name, result in results.items():
        row: dict[str, float | None] = dict(result.summary())
        row["capture"] = capture(float(result.returns.mean()), never, best)
        table[name] = row
    return table


def evaluate(
    env_id: str,
    policies: Mapping[str, Predictor],
    episodes: int = EVAL_EPISODES,
    seed: int = EVAL_SEED,
    progress: Callable[[str], None] | None = None,
) -> tuple[dict[str, Episodes], dict[str, dict[str, float | None]]]:
    """Run every policy on the same episodes; return raw results and the summary table."""
    results = {}
    for name, policy in policies.items():
        if progress is not None:
            progress(name)
        results[name] = run_episodes(env_id, policy, episodes, seed)
    return results, summarize(results)


def task_of(env_id: str) -> Any:
    """The unwrapped single environment of ``env_id``: its config, density and action kind."""
    check_env_id(env_id)
    env = gymnasium.make(env_id)
    env.close()
    return env.unwrapped


def hand_coded_policies(env_id: str) -> dict[str, Predictor]:
    """The hand-coded baselines (`HAND_CODED`), set up for ``env_id``'s config and action space."""
    base = task_of(env_id)
    return {name: cls(base.config, base.density, base.continuous) for name, cls in HAND_CODED.items()}


def paired_difference(
    results: Mapping[str, Episodes], name: str = "ppo", baseline: str | None = None
) -> dict[str, Any] | None:
    """``name``'s return minus ``baseline``'s, episode by episode (None if either is missing).

    ``baseline`` None: the best hand-coded policy. Both policies meet the same start
    states, so the per-episode difference has a much smaller spread than either
    return: its mean and standard error say whether a small lead is more than the
    luck of these episodes (``stderr`` None for a single episode, which has none).
    """
    if baseline is None:
        candidates = [b for b in HAND_CODED if b in results]
        baseline = max(candidates, key=lambda b: results[b].returns.mean()) if candidates else None
    if name not in results or baseline not in results:
        return None
    diff = results[name].returns - results[baseline].returns
    stderr = float(diff.std(ddof=1) / np.sqrt(diff.size)) if diff.size > 1 else None  # JSON null, never NaN
    return {
        "policy": name,
        "baseline": baseline,
        "mean": float(diff.mean()),
        "stderr": stderr,
        "better": int(np.sum(diff > TIE_DAYS)),
        "worse": int(np.sum(diff < -TIE_DAYS)),
    }


def policy_width(names: Iterable[str]) -> int:
    """Width of a table's policy column: 17 characters, or the longest name's."""
    return max([17, *(len(name) for name in names)])


def format_table(
    env_id: str,
    episodes: int,
    seed: int,
    table: Mapping[str, Mapping[str, float | None]],
    paired: Sequence[Mapping[str, Any]] = (),
) -> str:
    """The evaluation as a text table for people (``paired``: results of `paired_difference`)."""
    width = policy_width(table)
    spread = max([5, *(len(f"{row['std_return']:.1f}") for row in table.values())])  # 1020.9 too
    captured = any(row["capture"] is not None for row in table.values())  # else no capture column
    header = f"{'policy':<{width}} {'return':>{12 + spread}} {'lifetime [d]':>13} {'dv [m/s]':>9}"
    lines = [f"{env_id}: {episodes} episodes (seed {seed})", header + (f" {'capture':>8}" if captured else "")]
    for name, row in table.items():
        line = (
            f"{name:<{width}} {row['mean_return']:8.1f} +- {row['std_return']:{spread}.1f} "
            f"{row['mean_lifetime_days']:13.1f} {row['mean_dv_m_s']:9.1f}"
        )
        if captured:
            line += f" {'' if row['capture'] is None else format(row['capture'], '8.1%'):>8}"
        lines.append(line)
    if captured:
        lines.append("capture = (R - R_never) / (R_dp - R_never): the share of the optimum's improvement")
    for pair in paired:
        if pair["stderr"] is None:
            spread = f"{pair['mean']:+.2f} days (one episode: no standard error)"
        else:
            spread = f"{pair['mean']:+.2f} +- {pair['stderr']:.2f} days (mean +- s.e.)"
        lines.append(
            f"{pair['policy']} - {pair['baseline']}, paired: {spread}, better on {pair['better']}, "
            f"worse on {pair['worse']} episodes"
        )
    if paired:
        lines.append(f"paired: episode by episode on the same start states; ties within {TIE_DAYS} day")
    return "\n".join(lines)


def write_returns(results: Mapping[str, Episodes], path: str | Path) -> None:
    """Every episode's return [days], a row per episode and a column per policy (``episode`` first), as CSV."""
    names = list(results)
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["episode", *names])
        for k, values in enumerate(zip(*(results[name].returns for name in names), strict=True)):
            writer.writerow([k, *(repr(float(v)) for v in values)])


def plot_returns(results: Mapping[str, Episodes], env_id: str, path: str) -> None:
    """Box plot of the episode returns of every policy."""
    from orbit_env.optional import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=120)
    names = list(results)
    ax.boxplot([results[n].returns for n in names], showmeans=True)
    ax.set_xticks(range(1, len(names) + 1), names, rotation=30, ha="right")
    ax.set_ylabel("episode return [days - cost x m/s]")
    ax.set_title(f"{env_id}: returns on {next(iter(results.values())).returns.size} seeded episodes", fontsize=10)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


#: The shipped PPO model of each environment (under ``agents/models``), where there is one.
SHIPPED_MODELS = {
    "OrbitRaising-v0": "ppo_orbit_raising.zip",
    "OrbitRaisingUncertain-v0": "ppo_orbit_raising_uncertain.zip",
    "OrbitRaisingContinuous-v0": "ppo_orbit_raising_continuous.zip",
    "OrbitRaisingSolar-v0": "ppo_orbit_raising_solar.zip",
    "OrbitRaisingSolarContinuous-v0": "ppo_orbit_raising_solar_continuous.zip",
}


def model_algorithm(path: str | Path) -> str:
    """The algorithm of a saved Stable-Baselines3 model, read from its ``data`` (ValueError if none)."""
    import json
    import zipfile

    try:
        with zipfile.ZipFile(path) as archive:
            data = json.loads(archive.read("data"))
    except (OSError, KeyError, zipfile.BadZipFile, json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"{path} is not a Stable-Baselines3 model (a zip with its data): {error}") from None
    # Each algorithm saves its own hyperparameters; these tell them apart.
    for key, algorithm in (
        ("policy_delay", "td3"),
        ("target_entropy", "sac"),
        ("exploration_final_eps", "dqn"),
        ("clip_range", "ppo"),
        ("n_steps", "a2c"),
    ):
        if key in data:
            return algorithm
    raise ValueError(f"{path}: a model of none of the algorithms {', '.join(ALGORITHMS)}")


def _algorithm_class(algorithm: str) -> Any:
    try:
        import stable_baselines3
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(f"learned agents need stable-baselines3: {TRAIN_EXTRA}") from error
    return getattr(stable_baselines3, algorithm.upper())


def _space_text(space: Any) -> str:
    return f"Discrete({space.n})" if hasattr(space, "n") else f"Box{tuple(space.shape)}"


class ActingOnly:
    """Stands in for the optimizer of a model loaded to act (`load_model`): it cannot train."""

    def __init__(self, params: Any, lr: float = 0.0, **kwargs: Any) -> None:
        self.param_groups: list[Any] = []

    def load_state_dict(self, state: Any, strict: bool = True) -> None:
        """The saved optimizer state is not needed to act."""

    def state_dict(self) -> dict[str, Any]:
        """Nothing to save."""
        return {}

    def step(self, *args: Any, **kwargs: Any) -> None:
        """Refused: a model loaded to act does not train."""
        raise RuntimeError(
            "this model was loaded to act (orbit_env.agents.evaluate.load_model); load it with SB3 to train"
        )

    def zero_grad(self, *args: Any, **kwargs: Any) -> None:
        """Nothing to clear."""


def _no_schedule(_progress: float) -> float:
    """A training schedule's stand-in in a model loaded to act (`load_model`)."""
    return 0.0


def missing_learning_libraries() -> list[str]:
    """The learning libraries (torch, stable-baselines3) not installed: the [train] extra's."""
    from importlib.util import find_spec

    return [name for name in ("torch", "stable_baselines3") if find_spec(name) is None]


def load_model(
    env_id: str, model_path: str | Path | None = None, warn: Callable[[str], None] | None = None
) -> tuple[str, Predictor] | None:
    """The learned agent for ``env_id`` and its algorithm's name, checked before any heavy work.

    ``model_path`` None: the shipped model of ``env_id`` (None if there is none).
    The file must exist and load; its observation and action spaces must be the
    environment's; a model that records another environment (``orbit-env train``
    records it) gets a warning through ``warn``, as does one that records none, and one
    trained with settings of its env (a TOML's ``[env]`` table, its split aside).

    The model is loaded to act, not to train: its optimizer is `ActingOnly`
    (a torch optimizer would import torch's compiler, 1.4 s of CPU).

    It sets torch to one intra-op thread (``torch.set_num_threads(1)``): the
    evaluation's batches (up to 1000 observations of 7 through layers of 64) are
    too small to share, and threads that wait on a busy machine cost more than they
    give: 5.5 ms against 179 ms a batch of 1000 on two threads, measured on this
    project's 2-core machine under load.

    Raises:
        ValueError: a missing file, one that does not load, or spaces that do not fit.
    """
    from importlib import resources

    if env_id not in SOLAR_ENV_IDS:
        check_env_id(env_id)
    missing = missing_learning_libraries()
    if model_path is None:
        if env_id not in SHIPPED_MODELS:
            return None
        if missing:  # an installation without the [train] extra scores every other row
            if warn is not None:
                warn(f"the shipped agent's row is left out: it needs {' and '.join(missing)} ({TRAIN_EXTRA})")
            return None
        path = Path(str(resources.files("orbit_env.agents").joinpath("models", SHIPPED_MODELS[env_id])))
    else:
        path = Path(model_path)
    if not path.is_file():
        raise ValueError(f"no model at {path}")
    if missing:
        raise ValueError(f"a learned agent needs {' and '.join(missing)}: {TRAIN_EXTRA}")
    algorithm = model_algorithm(path)
    import torch
    from stable_baselines3.common.save_util import load_from_zip_file

    torch.set_num_threads(1)
    # What only training reads (schedules saved as closures, which another cloudpickle cannot rebuild: SB3 warned
    # "Could not deserialize object learning_rate" on every evaluation) is replaced, not unpickled.
    training_only = {"learning_rate": 0.0, "lr_schedule": _no_schedule, "clip_range": _no_schedule}
    try:
        data, _, _ = load_from_zip_file(path, device="cpu", custom_objects=training_only)
        kwargs = {**(data or {}).get("policy_kwargs", {}), "optimizer_class": ActingOnly}
        model = _algorithm_class(algorithm).load(
            path, device="cpu", custom_objects={**training_only, "policy_kwargs": kwargs}
        )
    except Exception as error:  # a damaged file fails in many ways: one line names it
        raise ValueError(
            f"{path} does not load as a {algorithm.upper()} model: {type(error).__name__}: {error}"
        ) from None
    base = gymnasium.make(env_id).unwrapped  # its spaces (the solar task has no task_of)
    for what, mine, theirs in (
        ("action", base.action_space, model.action_space),
        ("observation", base.observation_space, model.observation_space),
    ):
        if (
            not (isinstance(mine, type(theirs)) or isinstance(theirs, type(mine)))  # a subclass is the same space
            or getattr(mine, "n", None) != getattr(theirs, "n", None)
            or (mine.shape != theirs.shape)
        ):
            raise ValueError(
                f"{path} acts in the {what} space {_space_text(theirs)}, but {env_id} has {_space_text(mine)}"
            )
    recorded = getattr(model, "orbit_env", None) or {}
    trained_on = recorded.get("env_id")
    # The split is the evaluation's to choose (a solar agent trains on one, is scored on the other).
    settings = {k: v for k, v in (recorded.get("env") or {}).items() if k != "solar_split"}
    if warn is not None:
        if trained_on is None:
            warn(f"{path} does not record the environment it was trained on")
        elif trained_on != env_id:
            warn(f"{path} was trained on {trained_on}, not {env_id}")
        if settings:
            warn(
                f"{path} was trained with the env settings {settings}; it is scored here on {env_id} as registered, "
                "the task the yardsticks solve"
            )
    return algorithm, model


def all_policies(
    env_id: str,
    model_path: str | None = None,
    include_dp: bool = True,
    progress: Callable[[str], None] | None = None,
    warn: Callable[[str], None] | None = None,
    dp_lookahead: int = 1,
    dp_rollout: bool = False,
    learned_name: str | None = None,
) -> dict[str, Predictor]:
    """Hand-coded baselines, the DP optimum (if asked) and the learned agent, in `policy_order`.

    The learned agent (``model_path``, or the shipped one) is loaded and checked
    first (`load_model`), before the DP's solve; its row is named by its
    algorithm (``ppo``, ``a2c``, ...), or ``learned_name`` (listed last; not a
    baseline's or the DP's name). ``dp_lookahead``, ``dp_rollout``: the DP policy's (`dp_policy`).
    """
    if learned_name is not None and not learned_name.strip():
        raise ValueError(f"learned_name={learned_name!r} is blank; allowed: a row's name, or None (the algorithm's)")
    if learned_name is not None and learned_name in (*HAND_CODED, "dp"):
        raise ValueError(f"the learned agent's row may not be named {learned_name!r}: a baseline's or the DP's row")
    learned = load_model(env_id, model_path, warn)
    policies = hand_coded_policies(env_id)
    if include_dp:
        if progress is not None:
            progress("dp (solved on the first run, then read from the disk cache)")
        policies["dp"] = dp_policy(env_id, dp_lookahead, dp_rollout)
    name = None if learned is None else learned_name or learned[0]
    if learned is not None:
        policies[name] = learned[1]
    order = [*policy_order(), *([name] if name is not None and name not in policy_order() else [])]
    return {key: policies[key] for key in order if key in policies}


class ContinuousFromDiscrete:
    """Acts in the continuous variant with a policy over the discrete burn sizes (a = dv / max burn)."""

    def __init__(self, policy: Predictor, burn_sizes_m_s: tuple[float, ...], max_burn_m_s: float) -> None:
        self.policy = policy
        self.actions = np.clip(np.asarray(burn_sizes_m_s) / max_burn_m_s, 0.0, 1.0).astype(np.float32)

    def predict(self, observation: Any, state: Any = None, episode_start: Any = None, deterministic: bool = True):
        """The discrete policy's burn as a Box action."""
        index, state = self.policy.predict(observation, state, episode_start, deterministic)
        return self.actions[np.asarray(index)][..., None], state


#: DP grid of each of the oracle's rungs: coarser than ``orbit_env.agents.dp.DEFAULT_GRID``, as the
#: oracle holds all its rungs' solutions at once.
ORACLE_GRID = (96, 1, 1)


class OracleDP:
    """The optimum told the density: DP solutions on a ladder of density scales.

    In ``OrbitRaisingUncertain-v0`` every step it reads each satellite's true current
    density scale from the environment and acts by the DP solved at the nearest rung
    (log spacing, ``rungs`` over the scale range). It plans as if that scale then
    stayed constant, so with the slow solar-cycle drift it is a near-optimal
    reference, not an exact bound. Each rung's DP is solved on ``grid`` (default
    `ORACLE_GRID`).
    """

    def __init__(
        self,
        config: Any,
        scale_range: tuple[float, float],
        rungs: int = 9,
        grid: tuple[int, int, int] | None = None,
    ) -> None:
        from orbit_env.agents.dp import DPPolicy

        grid = ORACLE_GRID if grid is None else grid
        self.scales = np.geomspace(scale_range[0], scale_range[1], rungs)
        self.policies = [DPPolicy(config, grid=grid, density_scale=float(s)) for s in self.scales]
        self.env: Any = None
        self.rows: Any = None

    def bind(self, env: Any, rows: Any = None) -> None:
        """The vector env whose hidden density the oracle reads (None: none).

        ``rows``: whose observations come next (None: all). `run_episodes` binds it at every
        step and unbinds it at the end.
        """
        self.env = env
        self.rows = rows

    def predict(self, observation: Any, state: Any = None, episode_start: Any = None, deterministic: bool = True):
        """Each satellite acts by the DP of its density rung."""
        if self.env is None:
            raise ValueError(
                "OracleDP reads the hidden density of the episodes it is bound to: score it directly with "
                "run_episodes or evaluate (not inside another policy), or bind(vector_env) first"
            )
        obs = np.atleast_2d(np.asarray(observation))
        scale = self.env.state["density_scale"]
        scale = scale if self.rows is None else scale[self.rows]
        if scale.shape[0] != obs.shape[0]:
            raise ValueError(
                f"OracleDP is bound to {scale.shape[0]} satellites but was given {obs.shape[0]} observations"
            )
        rung = np.abs(np.log(scale)[:, None] - np.log(self.scales)[None, :]).argmin(axis=1)
        actions = np.zeros(obs.shape[0], dtype=np.int64)
        for k in np.unique(rung):
            mine = rung == k
            actions[mine] = self.policies[k].predict(obs[mine])[0]
        return actions, state


def dp_policy(env_id: str, lookahead: int = 1, rollout: bool = False) -> Predictor:
    """The optimum for ``env_id``: DP on the known density, its continuous form, or the oracle.

    The continuous variant's DP chooses among burns spaced by `CONTINUOUS_DP_STEP_M_S`:
    a lower bound on its optimum, converging as the spacing shrinks (see the constant).
    ``lookahead``: see `orbit_env.agents.dp.DPPolicy` (not for the oracle). ``rollout``:
    the rollout policy on the DP (`DPPolicy`'s ``rollout``) over pairs of burns
    (`ROLLOUT_DEPTH`) in the discrete variant; in the continuous one the DP's plans
    refined by a search over burn sizes and played (`orbit_env.agents.plan.PlanPolicy`).
    Not for the oracle.
    """
    from orbit_env.agents.dp import DPPolicy

    base = task_of(env_id)
    if base.density.scale_range[0] != base.density.scale_range[1]:
        if rollout or lookahead != 1:
            what = "the rollout" if rollout else f"the lookahead {lookahead}"
            raise ValueError(f"{env_id}: {what} needs a known, constant density (the DP's task)")
        return OracleDP(base.config, base.density.scale_range)
    scale = base.density.nominal_scale
    if base.continuous:
        sizes = continuous_dp_burns(base.config.max_burn_m_s)
        fine = dataclasses.replace(base.config, burn_sizes_m_s=sizes)
        policy = DPPolicy(fine, density_scale=scale, lookahead=lookahead)
        if rollout:
            from orbit_env.agents.plan import PlanPolicy

            return PlanPolicy(policy)
        return ContinuousFromDiscrete(policy, sizes, base.config.max_burn_m_s)
    return DPPolicy(base.config, density_scale=scale, lookahead=lookahead, rollout=ROLLOUT_DEPTH if rollout else 0)


#: Depth of the rollout policy on the discrete variant's DP: every pair of burns on the next two
#: steps is played before the base policy (single burns leave starts beaten by up to 0.17 day).
ROLLOUT_DEPTH = 2
#: Spacing of the burn sizes the DP of the continuous variant chooses from [m/s]. Measured on the
#: 1000 evaluation episodes (seed 12345, grid (192, 1, 1)), realized mean return: 278.05 (20 m/s,
#: solve and episodes 23 s, 0.5 GB), 278.21 (10 m/s, 54 s, 1.9 GB), 278.28 (5 m/s, 229 s, 6.6 GB);
#: docs/dp.md.
CONTINUOUS_DP_STEP_M_S = 10.0


def continuous_dp_burns(max_burn_m_s: float, step_m_s: float = CONTINUOUS_DP_STEP_M_S) -> tuple[float, ...]:
    """The burns 0, step, 2 step, ... up to ``max_burn_m_s`` (and it): the continuous action's grid for the DP."""
    count = max(math.floor(max_burn_m_s / step_m_s + 1e-9), 1)
    sizes = [k * step_m_s for k in range(count + 1) if k * step_m_s <= max_burn_m_s]
    if sizes[-1] < max_burn_m_s:
        sizes.append(max_burn_m_s)
    return tuple(sizes)
