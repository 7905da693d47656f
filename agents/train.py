"""PPO with Stable-Baselines3 on the numpy-batched vector environment (``orbit-env train``).

All hyperparameters live in a TOML file (default: ``agents/ppo.toml``, shipped with the
package); the run writes tensorboard logs, checkpoints and the final model to one
folder. The shipped model ``agents/models/ppo_orbit_raising.zip`` is this command's
output with the default file::

    orbit-env train --out runs/ppo && cp runs/ppo/model.zip agents/models/ppo_orbit_raising.zip
"""

from __future__ import annotations

import contextlib
import json
import math
import re
import signal
import threading
import time
import tomllib
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from orbit_env.optional import TRAIN_EXTRA

try:
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.logger import Logger, TensorBoardOutputFormat
    from stable_baselines3.common.utils import get_latest_run_id
    from stable_baselines3.common.vec_env import VecEnvWrapper
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError(f"training needs stable-baselines3 and torch: {TRAIN_EXTRA}") from error

from orbit_env.agents import VALIDATION_SEED  # the evaluation callback's (training uses the config's seed)
from orbit_env.agents.shaping import SHAPINGS
from orbit_env.analysis.catalogue_io import atomic_text
from orbit_env.checks import check_int

#: The hyperparameter file of the shipped model.
DEFAULT_CONFIG = "ppo.toml"
#: The run's tensorboard logs are in ``tensorboard/ppo_1/`` (SB3 numbers a log name's runs).
TB_LOG_NAME = "ppo"
#: A run's files beside ``checkpoints/`` and ``tensorboard/`` (``--force`` deletes them with the checkpoints).
_RUN_FILES = ("model.zip", "best_model.zip", "best_model_replaced.zip", "evaluations.json", "config.json")


@dataclass(frozen=True)
class TrainResult:
    """Where a training run left its files and how long it took."""

    model_path: Path
    log_dir: Path
    seconds: float
    timesteps: int  #: the model's timesteps in all (with a resumed checkpoint's)
    trained: int = 0  #: timesteps trained by this run
    best_model_path: Path | None = None  #: the evaluation callback's best model, if it ran


class BootstrapAtHorizon(VecEnvWrapper):
    """Mark the missions that reach the horizon as truncated, so that SB3 bootstraps the value past it.

    The environments end a mission terminated at re-entry and at the horizon alike (`orbit_env.envs`:
    the reward counts days within the mission and the clock is observed, Pardo et al. 2018, time limits
    in RL). ``bootstrap_at_horizon = true`` asks SB3 to add the value of the life after the mission
    anyway: SB3 reads ``infos[i]["TimeLimit.truncated"]``, set here where an episode ended without
    re-entering.
    """

    def reset(self) -> Any:
        """Reset the wrapped environments."""
        return self.venv.reset()

    def step_wait(self) -> Any:
        """Step, and mark each episode that ended in orbit (at the horizon) as truncated."""
        obs, rewards, dones, infos = self.venv.step_wait()
        for i in np.flatnonzero(dones):
            infos[i]["TimeLimit.truncated"] = not infos[i]["reentered"]
        return obs, rewards, dones, infos


#: Top-level keys of a training config: (type, default; None: required). Every key is checked.
TOP_KEYS: dict[str, tuple[type | tuple[type, ...], Any]] = {
    "env_id": (str, None),
    "seed": (int, None),
    "num_envs": (int, None),
    "total_timesteps": (int, None),
    "checkpoint_every": (int, 0),
    "eval_every": (int, 0),
    "eval_episodes": (int, 200),
    "bootstrap_at_horizon": (bool, True),
    "shaping": (str, "none"),
    "end_decided": ((int, float), 0.0),
    "learning_rate_schedule": (str, "constant"),
    "learning_rate_decay_start": ((int, float), 0.0),
}
#: Tables of a training config and the keys each takes (``env``: the environment's keywords).
POLICY_KEYS: dict[str, tuple[type | tuple[type, ...], Any]] = {
    "net_arch": (list, [64, 64]),
    "activation": (str, "tanh"),
    "initial_coast_logit": ((int, float), 0.0),
    "initial_action_mean": ((int, float), 0.0),
    "log_std_init": ((int, float), 0.0),
    "log_features": (bool, False),
}
NORMALIZE_KEYS: dict[str, tuple[type | tuple[type, ...], Any]] = {"reward": (bool, False)}
#: The policy network's activations by name.
ACTIVATIONS = ("tanh", "relu", "elu", "gelu", "leaky_relu")
#: PPO's constructor arguments a config may not set: the command sets them, or (a class and its arguments, which
#: the algorithm's own would repeat) TOML cannot give them.
_PPO_RESERVED = (
    "self",
    "policy",
    "env",
    "tensorboard_log",
    "policy_kwargs",
    "verbose",
    "seed",
    "device",
    "rollout_buffer_class",
    "rollout_buffer_kwargs",
)
#: The largest seed: NumPy's legacy generator, which Stable-Baselines3 seeds, takes 0 to 2**32 - 1.
MAX_SEED = 2**32 - 1
#: The largest initial logit or mean: the network's float32 holds 3.4e38, and the bias adds both.
_MAX_INITIAL = 1e38
#: Every number of a training config (a table's as ``table.key``) and what it may be, besides finite: (test, allowed).
#: The bounds are those Stable-Baselines3 and torch take, or those within which the value means what its name says
#: (a negative clip range trains without an error, on a clip inverted).
NUMBER_RANGES: dict[str, tuple[Callable[[float], bool], str]] = {
    "seed": (lambda x: 0 <= x <= MAX_SEED, f"an integer from 0 to {MAX_SEED} (NumPy's seeds)"),
    "num_envs": (lambda x: x >= 1, "an integer >= 1"),
    "total_timesteps": (lambda x: x >= 1, "an integer >= 1"),
    "checkpoint_every": (lambda x: x >= 0, "an integer >= 0 (0: none)"),
    "eval_every": (lambda x: x >= 0, "an integer >= 0 (0: none)"),
    "eval_episodes": (lambda x: x >= 1, "an integer >= 1"),
    "end_decided": (lambda x: 0 <= x <= 1, "a probability in [0, 1]"),
    "learning_rate_decay_start": (lambda x: 0 <= x < 1, "a fraction in [0, 1)"),
    "ppo.learning_rate": (lambda x: x > 0, "a number > 0"),
    "ppo.n_steps": (lambda x: x >= 1, "an integer >= 1"),
    "ppo.batch_size": (lambda x: x >= 1, "an integer >= 1"),
    "ppo.n_epochs": (lambda x: x >= 1, "an integer >= 1"),
    "ppo.gamma": (lambda x: 0 <= x <= 1, "a number in [0, 1]"),
    "ppo.gae_lambda": (lambda x: 0 <= x <= 1, "a number in [0, 1]"),
    "ppo.clip_range": (lambda x: x > 0, "a number > 0 (the ratio is clipped to 1 - clip_range, 1 + clip_range)"),
    "ppo.clip_range_vf": (lambda x: x > 0, "a number > 0 (leave the key out: the value is not clipped)"),
    "ppo.ent_coef": (lambda x: x >= 0, "a number >= 0"),
    "ppo.vf_coef": (lambda x: x >= 0, "a number >= 0"),
    "ppo.max_grad_norm": (lambda x: x > 0, "a number > 0"),
    "ppo.target_kl": (lambda x: x > 0, "a number > 0 (leave the key out: no early stop)"),
    "ppo.sde_sample_freq": (lambda x: x >= -1, "an integer >= -1 (-1: new noise at each rollout only)"),
    "ppo.stats_window_size": (lambda x: x >= 1, "an integer >= 1"),
    "policy.initial_coast_logit": (lambda x: abs(x) <= _MAX_INITIAL, "a number from -1e38 to 1e38 (float32)"),
    "policy.initial_action_mean": (lambda x: abs(x) <= _MAX_INITIAL, "a number from -1e38 to 1e38 (float32)"),
    # Stable-Baselines3's bounds of a Gaussian policy's log std (sac/policies.py LOG_STD_MIN, LOG_STD_MAX): beyond
    # them PPO's Gaussian overflows float32 in training.
    "policy.log_std_init": (lambda x: -20 <= x <= 2, "a number in [-20, 2] (Stable-Baselines3's log std bounds)"),
}


def _type_name(kind: type | tuple[type, ...]) -> str:
    names = {int: "an integer", float: "a number", bool: "true or false", str: "a string", list: "a list"}
    kinds = kind if isinstance(kind, tuple) else (kind,)
    return "a number" if float in kinds else names.get(kinds[0], kinds[0].__name__)


def _check_table(
    table: Any, schema: dict[str, tuple[type | tuple[type, ...], Any]], where: str, source: str
) -> dict[str, Any]:
    """The table with its defaults, after checking every key and type (ValueError on one line)."""
    if not isinstance(table, dict):
        raise ValueError(f"{source}: {where} must be a table")
    for key, value in table.items():
        if key not in schema:
            raise ValueError(f"{source}: unknown key {where}{key!r}; valid keys: {', '.join(schema)}")
        kind = schema[key][0]
        kinds = kind if isinstance(kind, tuple) else (kind,)
        if not isinstance(value, kinds) or (isinstance(value, bool) and bool not in kinds):
            raise ValueError(f"{source}: {where}{key} = {value!r} is invalid; allowed: {_type_name(kind)}")
    missing = [key for key, (_, default) in schema.items() if default is None and key not in table]
    if missing:
        raise ValueError(f"{source}: the key {where}{missing[0]!r} is missing")
    return {key: table.get(key, default) for key, (_, default) in schema.items()}


def _ppo_schema() -> dict[str, tuple[type | tuple[type, ...], Any]]:
    """The ``[ppo]`` keys: PPO's constructor arguments, typed by their defaults."""
    import inspect

    from stable_baselines3 import PPO

    schema: dict[str, tuple[type | tuple[type, ...], Any]] = {}
    for name, parameter in inspect.signature(PPO.__init__).parameters.items():
        if name in _PPO_RESERVED or name.startswith("_"):
            continue
        default = parameter.default
        if isinstance(default, bool):
            kind: type | tuple[type, ...] = bool
        elif isinstance(default, (int, float)):
            kind = (int, float) if isinstance(default, float) or name in ("learning_rate", "clip_range") else int
        else:  # None: off, or a number (clip_range_vf, target_kl)
            kind = (int, float)
        schema[name] = (kind, "absent")
    return schema


def load_config(path: str | Path | None = None) -> dict[str, Any]:
    """Read and check a training config (default: the shipped ``agents/ppo.toml``).

    ``agents/NAME.toml`` (or ``NAME.toml``) that is no file but a shipped recipe's name reads the shipped
    recipe: the docs write the recipes so, and a command typed outside the repository finds them. Every key
    is checked: an unknown key, a wrong type or value, a TOML syntax error or an env id that is not this
    package's is one ``ValueError`` line naming the file (and the line, for syntax), the key and what is
    allowed.
    """
    shipped = resources.files("orbit_env.agents")
    given = None if path is None else Path(path)
    name = DEFAULT_CONFIG if given is None else None  # a shipped recipe's, or None: the file ``given``
    if given is not None and given.parent in (Path("."), Path("agents")) and not given.is_file():
        if shipped.joinpath(given.name).is_file():
            name = given.name
            warnings.warn(f"{given} is no file here: reading the shipped recipe {name}", stacklevel=2)
    source = DEFAULT_CONFIG if path is None else str(path)
    try:
        text = shipped.joinpath(name).read_text() if name is not None else Path(str(given)).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"cannot read the training config {source}: {error}") from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ValueError(f"{source}: not valid TOML: {error}") from None
    tables = {"ppo": _ppo_schema(), "policy": POLICY_KEYS, "normalize": NORMALIZE_KEYS, "env": None}
    top = {key: value for key, value in raw.items() if key not in tables}
    for key in top:
        if key not in TOP_KEYS:
            valid = ", ".join([*TOP_KEYS, *(f"[{t}]" for t in tables)])
            raise ValueError(f"{source}: unknown key {key!r}; valid keys: {valid}")
    config = _check_table(top, TOP_KEYS, "", source)
    ppo = _check_table(raw.get("ppo", {}), tables["ppo"], "ppo.", source)
    config["ppo"] = {key: value for key, value in ppo.items() if value != "absent"}
    config["policy"] = _check_table(raw.get("policy", {}), POLICY_KEYS, "policy.", source)
    config["normalize"] = _check_table(raw.get("normalize", {}), NORMALIZE_KEYS, "normalize.", source)
    env_keywords = raw.get("env", {})
    if not isinstance(env_keywords, dict):
        raise ValueError(f"{source}: env must be a table of the environment's keywords")
    config["env"] = dict(env_keywords)
    _check_values(config, source)
    return config


def check_trainable(env_id: str, given: str) -> None:
    """ValueError unless ``env_id`` is an environment of this package; ``given`` says where it came from.

    ``given`` begins the message: ``ppo.toml: env_id = 'Nope-v0'``, ``env_id='Nope-v0'``, ``--env Nope-v0``.
    """
    from orbit_env.envs import ENV_IDS, SOLAR_ENV_IDS

    allowed = (*ENV_IDS, *SOLAR_ENV_IDS)
    if env_id not in allowed:
        raise ValueError(f"{given} is not an orbit_env environment; allowed: {', '.join(allowed)}")


def _check_overrides(overrides: dict[str, Any]) -> None:
    """The arguments of `train` that override the config, named as the caller gave them (not as the file's keys)."""
    for key in ("num_envs", "total_timesteps"):
        if overrides[key] is not None:
            check_int(overrides[key], key, low=1)
    if overrides["seed"] is not None:
        check_int(overrides["seed"], "seed", low=0, high=MAX_SEED)
    if overrides["env_id"] is not None:
        check_trainable(overrides["env_id"], f"env_id={overrides['env_id']!r}")


def _check_values(config: dict[str, Any], source: str) -> None:
    """The values' ranges and the combinations that cannot work (ValueError naming the key).

    Every number against `NUMBER_RANGES`, so that nothing that passes fails in Stable-Baselines3 or torch
    after the run's folder is written (its asserts, a NaN in the network) or trains on a value that means
    nothing.
    """
    from orbit_env.envs import SOLAR_ENV_IDS

    check_trainable(config["env_id"], f"{source}: env_id = {config['env_id']!r}")
    for key, (allowed, text) in NUMBER_RANGES.items():
        table, _, name = key.rpartition(".")
        values = config[table] if table else config
        if name in values and not (math.isfinite(values[name]) and allowed(values[name])):
            raise ValueError(f"{source}: {key} = {values[name]!r} is invalid; allowed: {text}")
    if config["learning_rate_schedule"] not in ("constant", "linear"):
        raise ValueError(
            f"{source}: learning_rate_schedule = {config['learning_rate_schedule']!r} is invalid; "
            "allowed: constant, linear"
        )
    if config["shaping"] not in SHAPINGS:
        raise ValueError(f"{source}: shaping = {config['shaping']!r} is invalid; allowed: {', '.join(SHAPINGS)}")
    if config["env_id"] in SOLAR_ENV_IDS and config["shaping"] != "none":
        raise ValueError(
            f'{source}: shaping = {config["shaping"]!r} is invalid for {config["env_id"]}; allowed: "none" '
            "(never_burn_value reads the known-density task's curves)"
        )
    if config["end_decided"] > 0.0 and config["shaping"] != "never_burn_value":
        raise ValueError(
            f'{source}: end_decided > 0 needs shaping = "never_burn_value" (it ends episodes on its potential)'
        )
    policy = config["policy"]
    if policy["activation"] not in ACTIVATIONS:
        raise ValueError(
            f"{source}: policy.activation = {policy['activation']!r} is invalid; allowed: {', '.join(ACTIVATIONS)}"
        )
    arch = policy["net_arch"]
    if not arch or not all(isinstance(n, int) and not isinstance(n, bool) and n >= 1 for n in arch):
        raise ValueError(f"{source}: policy.net_arch = {arch!r} is invalid; allowed: a list of layer widths >= 1")
    ppo = config["ppo"]
    if ppo.get("normalize_advantage", True):  # PPO's asserts: the advantages are normalized over a batch
        if ppo.get("batch_size", 64) < 2:
            raise ValueError(
                f"{source}: ppo.batch_size = {ppo['batch_size']} is invalid; allowed: an integer >= 2 "
                "(the advantages are normalized over a batch; or normalize_advantage = false)"
            )
        if rollout_size(config) < 2:
            raise ValueError(
                f"{source}: ppo.n_steps x num_envs = {rollout_size(config)} is invalid; allowed: at least 2 "
                "(the advantages are normalized over a rollout; or normalize_advantage = false)"
            )
    continuous = _check_env_keywords(config["env_id"], config["env"], source)
    if ppo.get("use_sde") and not continuous:
        raise ValueError(
            f"{source}: ppo.use_sde = true is invalid for {config['env_id']}; allowed: false "
            "(state-dependent exploration is for continuous actions)"
        )


def _check_env_keywords(env_id: str, keywords: dict[str, Any], source: str) -> bool:
    """The ``[env]`` table makes the environment (ValueError naming the bad keyword); whether its actions are a Box."""
    import gymnasium

    import orbit_env  # noqa: F401  (registers the environments)

    try:
        env = gymnasium.make(env_id, **keywords)
    except ValueError as error:
        raise ValueError(f"{source}: [env] {error}") from None
    env.close()
    return isinstance(env.action_space, gymnasium.spaces.Box)


def linear_decay(rate: float, start: float = 0.0) -> Callable[[float], float]:
    """Learning rate ``rate`` until the fraction ``start`` of the run, then linearly down to 0 at its end.

    SB3 calls the schedule with the progress left, from 1 down to 0.
    """
    left_at_start = 1.0 - start
    return lambda progress_left: rate * min(1.0, progress_left / left_at_start)


def rollout_size(config: dict[str, Any]) -> int:
    """Transitions per PPO update: ``n_steps`` (SB3's default 2048) times ``num_envs``."""
    return int(config["ppo"].get("n_steps", 2048)) * int(config["num_envs"])


def timesteps_to_train(requested: int, config: dict[str, Any]) -> int:
    """``requested`` rounded up to whole rollouts: what SB3 trains (and the progress bar counts)."""
    size = rollout_size(config)
    return -(-int(requested) // size) * size


class BestModelCallback(BaseCallback):
    """Score the policy on the same seeded episodes of the plain environment; keep the best model.

    At the first rollout boundary at or past every ``every_calls`` steps of the vector env
    (`due_between_rollouts`), and at the end through `train`, it plays one episode per
    sub-environment of ``gymnasium.make_vec(env_id, num_envs=episodes, **env_kwargs)``
    seeded with ``seed`` (`orbit_env.agents.evaluate.run_episodes`: the
    unshaped reward, deterministic actions; on the solar task the missions of
    `orbit_env.agents.solar.fly_model`, on the split of ``env_kwargs``), logs ``eval/mean_reward`` to
    tensorboard, saves the best so far to ``save_dir/best_model.zip`` and every
    score to ``save_dir/evaluations.json``. SB3's ``EvalCallback`` draws new
    episodes each time and would compare the policies on different starts.

    Args:
        env_id: The environment trained on.
        env_kwargs: Its keywords (the config's ``[env]`` table).
        every_calls: Steps of the vector env between evaluations (>= 1).
        episodes: Episodes per evaluation.
        seed: Seed of the episodes.
        save_dir: Folder of ``best_model.zip`` and ``evaluations.json``.
        resume: The timesteps of the checkpoint a resumed run continues from: the scores of
            ``save_dir/evaluations.json`` up to it are continued (a new model is saved only if it
            beats them); those after it were of the run being replaced and are dropped, and if
            one of them made ``best_model.zip``, that file is kept as ``best_model_replaced.zip`` and
            this branch's first score makes a new one (the kept scores' model was overwritten).
    """

    def __init__(
        self,
        env_id: str,
        env_kwargs: dict[str, Any],
        every_calls: int,
        episodes: int,
        seed: int,
        save_dir: str | Path,
        resume: int | None = None,
    ) -> None:
        super().__init__(verbose=0)
        if isinstance(resume, bool):
            raise ValueError(f"resume={resume!r} is invalid; allowed: None or the checkpoint's timesteps")
        self.env_id = env_id
        self.env_kwargs = dict(env_kwargs)
        self.every_calls = max(int(every_calls), 1)
        self.episodes = int(episodes)
        self.seed = int(seed)
        self.save_dir = Path(save_dir)
        self.best_mean = -float("inf")
        self.evaluations: list[dict[str, float]] = []
        if resume is not None and (self.save_dir / "evaluations.json").is_file():
            # A resumed run's best model stays the best unless beaten; the scores after its checkpoint are
            # of the branch it replaces (a checkpoint older than the last score: they would appear twice).
            try:
                scores = json.loads((self.save_dir / "evaluations.json").read_text())
            except json.JSONDecodeError as error:
                raise ValueError(f"{self.save_dir / 'evaluations.json'} is not readable JSON ({error})") from None
            self.evaluations = [e for e in scores if e["timesteps"] <= resume]
            self.best_mean = max((e["mean_return"] for e in self.evaluations), default=-float("inf"))
            replaced = max((e["mean_return"] for e in scores if e["timesteps"] > resume), default=-float("inf"))
            if replaced > self.best_mean and self.best_model_path.is_file():
                self.best_model_path.replace(self.save_dir / "best_model_replaced.zip")
                self.best_mean = -float("inf")  # no file holds the kept scores' best: the next score is saved

    @property
    def best_model_path(self) -> Path:
        """Where the best model goes."""
        return self.save_dir / "best_model.zip"

    def _on_step(self) -> bool:
        return True

    def _on_rollout_start(self) -> None:
        last = self.evaluations[-1]["timesteps"] if self.evaluations else 0
        if due_between_rollouts(last, self.model.num_timesteps, self.every_calls * self.model.n_envs):
            self.evaluate()

    def evaluate(self) -> float:
        """Score the current policy now; save it if it is the best so far; return its mean return."""
        from orbit_env.agents.evaluate import run_episodes
        from orbit_env.envs import SOLAR_ENV_IDS

        if self.env_id in SOLAR_ENV_IDS:
            from orbit_env.agents.solar import fly_model

            result = fly_model(self.model, self.episodes, self.seed, self.env_kwargs, self.env_id).episodes()
        else:
            result = run_episodes(self.env_id, self.model, self.episodes, self.seed, env_kwargs=self.env_kwargs)
        mean = float(result.returns.mean())
        self.logger.record("eval/mean_reward", mean)
        self.save_dir.mkdir(parents=True, exist_ok=True)
        if mean > self.best_mean:
            self.best_mean = mean
            _save_whole(self.model, self.best_model_path)
        self.logger.record("eval/best_mean_reward", self.best_mean)
        self.evaluations.append({"timesteps": int(self.model.num_timesteps), "mean_return": mean})
        with atomic_text(self.save_dir / "evaluations.json") as handle:
            handle.write(json.dumps(self.evaluations, indent=1) + "\n")
        return mean


def training_env(config: dict[str, Any]) -> Any:
    """The SB3 ``VecEnv`` a checked training config trains on, without reward normalization.

    `orbit_env.envs.sb3.make_sb3_vec_env` unmonitored, then `BootstrapAtHorizon`
    (``bootstrap_at_horizon = true``), the reward shaping, and one ``VecMonitor``
    above them all, which sees the episodes PPO is trained on (with shaping, each
    episode's ``mission_return`` beside, for `ReturnsCallback`).
    """
    from stable_baselines3.common.vec_env import VecMonitor

    from orbit_env.envs.sb3 import make_sb3_vec_env

    seed = int(config["seed"])
    venv: Any = make_sb3_vec_env(
        config["env_id"], num_envs=int(config["num_envs"]), seed=seed, monitor=False, **config["env"]
    )
    if config["bootstrap_at_horizon"]:
        venv = BootstrapAtHorizon(venv)
    if config["shaping"] == "never_burn_value":
        from orbit_env.agents.shaping import never_burn_value_shaping

        # Before VecNormalize: it scales the shaped reward.
        venv = never_burn_value_shaping(venv, end_decided=float(config["end_decided"]), seed=seed)
        # Episode returns and lengths for tensorboard, and the mission's return beside the shaped one.
        return VecMonitor(venv, info_keywords=("mission_return",))
    return VecMonitor(venv)  # episode returns and lengths for tensorboard: the mission's own


class ReturnsCallback(BaseCallback):
    """Log the return PPO is trained on and the mission's return, under names nobody confuses.

    After every rollout, over SB3's last 100 finished training episodes (actions
    sampled from the policy):

    * ``mission/return``: the mission's return as ``orbit-env evaluate`` scores it,
      the plain environment's reward over the whole mission (an episode the shaping
      ended early counts what coasting on earns, ``infos[i]["mission_return"]`` of
      `orbit_env.agents.shaping.NeverBurnValueShaping`);
    * ``rollout/shaped_return``, with shaping only: the shaped, early-ended return PPO
      maximizes (the mission's less the start's potential), which is also what SB3's
      own ``rollout/ep_rew_mean`` shows then.

    Args:
        shaped: Whether the training env shapes its reward.
    """

    def __init__(self, shaped: bool) -> None:
        super().__init__()
        self.shaped = shaped

    def _on_step(self) -> bool:
        return True

    def _on_rollout_end(self) -> None:
        episodes = self.model.ep_info_buffer
        if not episodes:
            return
        self.logger.record("mission/return", float(np.mean([e.get("mission_return", e["r"]) for e in episodes])))
        if self.shaped:
            self.logger.record("rollout/shaped_return", float(np.mean([e["r"] for e in episodes])))


class TrainingInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM) stopped `train`; ``checkpoint`` holds the run up to its last whole rollout."""

    def __init__(self, checkpoint: Path, timesteps: int) -> None:
        super().__init__(f"interrupted; saved {checkpoint} ({timesteps} timesteps)")
        self.checkpoint = checkpoint
        self.timesteps = timesteps

    def __reduce__(self) -> tuple[Any, ...]:  # raised in a worker process, it reaches the parent whole
        return TrainingInterrupted, (self.checkpoint, self.timesteps)


def _written_whole(path: Path, write: Callable[[Path], object]) -> None:
    """``write(file)`` into ``.partial/`` beside ``path``, then the file moved to ``path`` (a rename: whole or absent).

    For the files a library writes by its name (SB3's zip, VecNormalize's pickle); text goes through
    `orbit_env.analysis.catalogue_io.atomic_text`. Ctrl-C and SIGTERM wait for the write (`_interrupts_held`).
    """
    partial = path.parent / ".partial"
    partial.mkdir(parents=True, exist_ok=True)
    with _interrupts_held():
        write(partial / path.name)
        (partial / path.name).replace(path)


@contextlib.contextmanager
def _interrupts_held() -> Iterator[None]:
    """Ctrl-C and SIGTERM arriving in the block are delivered when it ends, as they would have been.

    An interrupt inside torch's zip writer had been replaced by the writer's own error on closing the
    cut file ("unexpected pos"), so a SIGTERM during a checkpoint ended training with a traceback and
    exit status 1 instead of the interrupted run's checkpoint and 130. Python runs signal handlers in the
    main thread only: elsewhere the block runs as it is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    held = [s for s in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(s) is not None]
    previous = {s: signal.signal(s, lambda signum, frame: caught.append(signum)) for s in held}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        for signum in caught:
            signal.raise_signal(signum)  # to the handler the block held it from (KeyboardInterrupt, the CLI's, ...)


def _save_whole(model: Any, path: Path) -> None:
    """``model.save(path)`` without the env, written whole (`_written_whole`)."""
    _written_whole(path, lambda file: model.save(file, exclude=["env", "tensorboard_log"]))


def save_checkpoint(model: Any, folder: Path, timesteps: int) -> Path:
    """``rl_model_N_steps.zip`` (N = ``timesteps``) and its reward statistics, each written whole or not at all.

    Each file is written in ``folder/.partial`` and moved into ``folder`` (a rename, atomic): the
    statistics first, so that a checkpoint that exists has them (a run killed while SB3's own callback
    wrote had left a 0-byte or truncated zip, or a zip without its statistics, which resumed with fresh ones).
    """
    path = folder / f"rl_model_{timesteps}_steps.zip"
    normalize = model.get_vec_normalize_env()
    if normalize is not None:
        _written_whole(_vecnormalize_path(path), lambda file: normalize.save(str(file)))
    _save_whole(model, path)
    return path


def due_between_rollouts(last: int, now: int, every: int) -> bool:
    """Whether a periodic callback acts at ``now`` timesteps, called between rollouts, having acted at ``last``.

    It acts at the first rollout boundary at or past each multiple of ``every`` timesteps. Between rollouts the
    policy has been updated on every timestep counted, so a checkpoint or a score taken there is of the policy
    its step count names. Taken on a step inside a rollout, as SB3's ``CheckpointCallback`` and ``EvalCallback``
    take them, it would be of a policy not yet updated on up to a rollout's steps (10M with 20000 satellites),
    and a run resumed from such a checkpoint would skip them.
    """
    every = max(int(every), 1)
    return now >= (last // every + 1) * every


class CheckpointEvery(BaseCallback):
    """`save_checkpoint` every ``every_calls`` steps of the vector env, between rollouts, and at the end.

    SB3's CheckpointCallback, its files whole and taken where the policy is the one their names count
    (`due_between_rollouts`).
    """

    def __init__(self, every_calls: int, folder: Path) -> None:
        super().__init__(verbose=0)
        self.every_calls = max(int(every_calls), 1)
        self.folder = folder
        self.last = 0

    def _on_training_start(self) -> None:
        self.last = int(self.model.num_timesteps)  # a resumed run's checkpoint is there already

    def _on_step(self) -> bool:
        return True

    def _on_rollout_start(self) -> None:
        self._save_when_due()

    def _on_training_end(self) -> None:  # after the last update
        self._save_when_due()

    def _save_when_due(self) -> None:
        now = int(self.model.num_timesteps)
        if due_between_rollouts(self.last, now, self.every_calls * self.model.n_envs):
            save_checkpoint(self.model, self.folder, now)
            self.last = now


def newest_checkpoint(out_dir: str | Path) -> Path | None:
    """The checkpoint of most timesteps in ``out_dir/checkpoints`` (``rl_model_N_steps.zip``), or None."""
    folder = Path(out_dir, "checkpoints")
    if not folder.is_dir():
        return None
    found = [
        (int(m[1]), folder / m[0])
        for p in folder.iterdir()
        if (m := re.fullmatch(r"rl_model_(\d+)_steps\.zip", p.name))
    ]
    return max(found)[1] if found else None


class _ResumedTensorBoard(TensorBoardOutputFormat):
    """SB3's tensorboard output whose writer hides the events logged before it at and after ``purge_step``."""

    def __init__(self, folder: str, purge_step: int) -> None:  # the base's two attributes, its writer purging
        from torch.utils.tensorboard import SummaryWriter

        self.writer = SummaryWriter(log_dir=folder, purge_step=purge_step)
        self._is_closed = False


def resumed_logger(tensorboard: Path, timesteps: int) -> Logger:
    """The logger of a run resumed at ``timesteps``: its tensorboard folder continued, its later events hidden.

    A run killed past its last checkpoint (SIGKILL, a crash), or resumed from an older checkpoint, had logged
    the timesteps it then trains again, and TensorBoard drew both (each curve doubling back on itself). The
    writer's ``purge_step`` hides the earlier events after the checkpoint's timesteps (those at them were
    logged by the rollouts the checkpoint holds). The folder is the one SB3 continues (``ppo_N``, the newest).
    """
    run = tensorboard / f"{TB_LOG_NAME}_{max(get_latest_run_id(str(tensorboard), TB_LOG_NAME), 1)}"
    return Logger(folder=str(run), output_formats=[_ResumedTensorBoard(str(run), timesteps + 1)])


def _vecnormalize_path(checkpoint: Path) -> Path:
    """The reward statistics `save_checkpoint` writes beside ``rl_model_N_steps.zip`` (SB3's own naming)."""
    return checkpoint.with_name(checkpoint.name.replace("rl_model_", "rl_model_vecnormalize_")).with_suffix(".pkl")


def train(
    config_path: str | Path | None = None,
    out_dir: str | Path = "runs/ppo",
    *,
    total_timesteps: int | None = None,
    seed: int | None = None,
    num_envs: int | None = None,
    env_id: str | None = None,
    resume: str | Path | None = None,
    force: bool = False,
    progress: bool = True,
    extra_callbacks: Sequence[Any] = (),
) -> TrainResult:
    """Train PPO as the config says; return where the model went.

    The arguments other than ``config_path`` override the config. Episode returns go
    to tensorboard: ``mission/return``, the mission's return as ``orbit-env evaluate``
    scores it, and with shaping ``rollout/shaped_return``, the shaped, early-ended
    return PPO maximizes (`ReturnsCallback`; SB3's ``rollout/ep_rew_mean`` is the
    return PPO is trained on); with ``eval_every``, the plain env's mean return on
    fixed validation episodes with deterministic actions (``eval/mean_reward``,
    `BestModelCallback`).

    Args:
        config_path: TOML file of hyperparameters (default: the shipped one).
        out_dir: Folder for ``model.zip``, ``best_model.zip``, ``checkpoints/`` and ``tensorboard/``.
        total_timesteps: The run's budget, rounded up to whole rollouts (default: the config's).
        seed: Seed of the run (default: the config's).
        num_envs: Satellites stepped together (default: the config's).
        env_id: Environment (default: the config's ``env_id``); the ``[env]`` keywords still apply.
        resume: A checkpoint (``checkpoints/rl_model_N_steps.zip``) to continue from,
            up to the same total budget, under the run's settings (``config.json``).
        force: Start over in ``out_dir``, deleting the run there, finished or not (otherwise it is
            kept: ValueError); with ``resume``, replace a finished run's model.
        progress: Show a progress bar.
        extra_callbacks: More SB3 callbacks that see the training (`orbit_env.agents.curves` scores the policy).

    Raises:
        ValueError: a bad config or argument, a run in ``out_dir`` without ``force`` (or
            ``resume`` for an unfinished one), a missing checkpoint, a resume under other settings.
        TrainingInterrupted: Ctrl-C (or SIGTERM through the command line) stopped the run: its
            checkpoint at the last whole rollout is saved (``checkpoint``), the run can be resumed from it.
    """
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import ProgressBarCallback
        from stable_baselines3.common.logger import configure as configure_logger
        from stable_baselines3.common.vec_env import VecNormalize
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError("training needs stable-baselines3 and torch: pip install 'orbit-env[train]'") from error

    import orbit_env  # noqa: F401  (registers the environments)

    config = load_config(config_path)
    source = DEFAULT_CONFIG if config_path is None else str(config_path)
    overrides = {"total_timesteps": total_timesteps, "seed": seed, "num_envs": num_envs, "env_id": env_id}
    _check_overrides(overrides)  # a bad argument is the argument's, not the file's
    for key, value in overrides.items():
        if value is not None:
            config[key] = value
    _check_values(config, source)
    out = Path(out_dir)
    model_path = out / "model.zip"
    checkpoint = None if resume is None else Path(resume)
    if checkpoint is not None and not checkpoint.is_file():
        raise ValueError(f"no checkpoint at {checkpoint}")
    # A resume continues the checkpoint's run (the settings of the run folder its checkpoints/ is in, else of
    # --out's), up to its budget unless --timesteps gives another.
    started_path = None
    if checkpoint is not None:
        folder = checkpoint.resolve().parent
        started_path = (folder.parent if folder.name == "checkpoints" else out) / "config.json"
    if started_path is not None and started_path.is_file():
        try:
            started = json.loads(started_path.read_text())
        except json.JSONDecodeError:
            started = None
        if not (isinstance(started, dict) and "total_timesteps" in started):
            raise ValueError(f"{started_path} is not a training run's settings (orbit-env train writes them)")
        if total_timesteps is None:
            config["total_timesteps"] = started["total_timesteps"]
        changed = sorted(key for key in {*started, *config} if started.get(key) != config.get(key))
        changed = [key for key in changed if key != "total_timesteps"]
        if changed:
            raise ValueError(
                f"{checkpoint} is of a run trained with other settings ({', '.join(changed)} differ from "
                f"{started_path}): give the run's --config and options to resume it (--timesteps may change)"
            )
    timesteps = timesteps_to_train(config["total_timesteps"], config)
    if model_path.exists() and not force:
        if checkpoint is None:
            raise ValueError(f"{model_path} exists: a finished run is kept; pass --force to overwrite it")
        raise ValueError(f"{model_path} exists: resuming from {checkpoint} would replace a finished run; pass --force")
    newest = newest_checkpoint(out)
    if checkpoint is None and not model_path.exists() and not force and (newest or (out / "evaluations.json").exists()):
        named = f"; continue it with --resume {newest}" if newest is not None else ""
        raise ValueError(f"{out} holds an unfinished run{named}, or pass --force to start over (its files deleted)")
    if force and checkpoint is None:  # a new run: the old one's files would mix with its own
        for old in [*Path(out, "checkpoints").glob("rl_model_*"), *(out / name for name in _RUN_FILES)]:
            old.unlink(missing_ok=True)
    out.mkdir(parents=True, exist_ok=True)
    with atomic_text(out / "config.json") as handle:  # the run's settings, so that a resume continues the same run
        handle.write(json.dumps(config, indent=1, sort_keys=True) + "\n")
    torch.set_num_threads(1)  # small networks: threads cost more than they give on 2 cores
    seed = int(config["seed"])
    venv: Any = training_env(config)
    gamma = float(config["ppo"].get("gamma", 0.99))
    if config["normalize"]["reward"]:
        stats = None if checkpoint is None else _vecnormalize_path(checkpoint)
        if stats is not None and stats.is_file():
            venv = VecNormalize.load(str(stats), venv)
        else:
            venv = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=gamma)
    if checkpoint is not None:
        model = PPO.load(checkpoint, env=venv, device="cpu", tensorboard_log=str(out / "tensorboard"))
        model.set_random_seed((seed + int(model.num_timesteps)) % (MAX_SEED + 1))
        model.set_logger(resumed_logger(out / "tensorboard", int(model.num_timesteps)))
    else:
        model = _new_model(PPO, torch, config, venv, out)
    model.orbit_env = {"env_id": config["env_id"], "env": dict(config["env"])}  # saved with the model
    callbacks: list[Any] = [ReturnsCallback(shaped=config["shaping"] != "none")]
    every = int(config["checkpoint_every"])
    calls = lambda steps: max(steps // int(config["num_envs"]), 1)  # noqa: E731  (timesteps -> env steps)
    if every > 0:
        callbacks.append(CheckpointEvery(calls(every), out / "checkpoints"))
    best = None
    if config["eval_every"] > 0:
        best = BestModelCallback(
            config["env_id"],
            config["env"],
            calls(config["eval_every"]),
            config["eval_episodes"],
            VALIDATION_SEED,
            out,
            resume=None if checkpoint is None else int(model.num_timesteps),
        )
        callbacks.append(best)
    callbacks.extend(extra_callbacks)
    remaining = max(timesteps - int(model.num_timesteps), 0)
    # The bar is this function's own, so that an interrupt can close it: a live rich bar would wrap (and
    # redraw around) the lines printed after it.
    bar = ProgressBarCallback() if progress and remaining > 0 else None
    start = time.perf_counter()
    try:
        if remaining > 0:
            model.learn(
                total_timesteps=remaining,
                callback=[*callbacks, *([bar] if bar is not None else [])],
                tb_log_name=TB_LOG_NAME,
                reset_num_timesteps=checkpoint is None,
            )
        if best is not None and (not best.evaluations or best.evaluations[-1]["timesteps"] != model.num_timesteps):
            if remaining == 0:  # resumed at its budget (stopped in its final evaluation): learn set up nothing
                model.set_logger(configure_logger(None, []))
                best.init_callback(model)
            best.evaluate()  # the final policy competes too
            model.logger.dump(model.num_timesteps)  # learn has written its last logs: its score to tensorboard
        seconds = time.perf_counter() - start
        _save_whole(model, model_path)
    except KeyboardInterrupt:
        if bar is not None and getattr(bar, "pbar", None) is not None:
            bar.pbar.close()
        # Kept up to the last whole rollout: one being collected is collected again on resuming; an update
        # stopped part way keeps the epochs it finished.
        rollout = int(config["ppo"].get("n_steps", 2048)) * int(config["num_envs"])
        model.num_timesteps = int(model.num_timesteps) // rollout * rollout
        saved = save_checkpoint(model, out / "checkpoints", model.num_timesteps)
        raise TrainingInterrupted(saved, model.num_timesteps) from None
    return TrainResult(
        model_path=model_path,
        log_dir=out / "tensorboard",
        seconds=seconds,
        timesteps=int(model.num_timesteps),
        trained=remaining,
        best_model_path=None if best is None else best.best_model_path,
    )


def _new_model(ppo_class: Any, torch: Any, config: dict[str, Any], venv: Any, out: Path) -> Any:
    """A fresh PPO as the config's ``[ppo]`` and ``[policy]`` say."""
    policy = config["policy"]
    activation = {
        "tanh": torch.nn.Tanh,
        "relu": torch.nn.ReLU,
        "elu": torch.nn.ELU,
        "gelu": torch.nn.GELU,
        "leaky_relu": torch.nn.LeakyReLU,
    }[policy["activation"]]
    policy_kwargs: dict[str, Any] = {"net_arch": list(policy["net_arch"]), "activation_fn": activation}
    if policy["log_features"]:
        from orbit_env.agents.features import LogFeatures

        policy_kwargs["features_extractor_class"] = LogFeatures
    if policy["log_std_init"]:
        policy_kwargs["log_std_init"] = float(policy["log_std_init"])
    ppo_kwargs = dict(config["ppo"])
    if config["learning_rate_schedule"] == "linear":
        ppo_kwargs["learning_rate"] = linear_decay(
            float(ppo_kwargs.get("learning_rate", 3e-4)), float(config["learning_rate_decay_start"])
        )
    model = ppo_class(
        "MlpPolicy",
        venv,
        seed=int(config["seed"]),
        verbose=0,
        device="cpu",
        tensorboard_log=str(out / "tensorboard"),
        policy_kwargs=policy_kwargs,
        **ppo_kwargs,
    )
    with torch.no_grad():
        # Burns are rare decisions: a uniform initial policy burns a third of the time and
        # empties the tank in days, so it never learns what keeping propellant is worth.
        # Discrete: the coast's logit; continuous: the Gaussian's mean (a < 0 coasts).
        model.policy.action_net.bias[0] += float(policy["initial_coast_logit"]) + float(policy["initial_action_mean"])
    return model
