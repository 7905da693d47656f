"""PPO with Stable-Baselines3 on the numpy-batched vector environment (``orbit-env train``).

All hyperparameters live in a TOML file (default: ``agents/ppo.toml``, shipped with the
package); the run writes tensorboard logs, checkpoints and the final model to one
folder. The shipped model ``agents/models/ppo_orbit_raising.zip`` is this command's
output with the default file::

    orbit-env train --out runs/ppo && cp runs/ppo/model.zip agents/models/ppo_orbit_raising.zip
"""

from __future__ import annotations

import time
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

try:
    from stable_baselines3.common.vec_env import VecEnvWrapper
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError("training needs stable-baselines3 and torch: pip install 'orbit-env[train]'") from error

from orbit_env.agents.shaping import SHAPINGS

#: The hyperparameter file of the shipped model.
DEFAULT_CONFIG = "ppo.toml"


@dataclass(frozen=True)
class TrainResult:
    """Where a training run left its files and how long it took."""

    model_path: Path
    log_dir: Path
    seconds: float
    timesteps: int


class MissionEndIsTerminal(VecEnvWrapper):
    """Treat the horizon as the end of the task: no value bootstrapped past it.

    The environments reward days *within* the mission and show the mission clock,
    so the state at the horizon is terminal for the task; SB3 would otherwise add
    the value of the life after the mission (Pardo et al. 2018, time limits in RL).
    """

    def reset(self) -> Any:
        """Reset the wrapped environments."""
        return self.venv.reset()

    def step_wait(self) -> Any:
        """Step, and drop SB3's truncation marks so that the horizon counts as terminal."""
        obs, rewards, dones, infos = self.venv.step_wait()
        for info in infos:
            info.pop("TimeLimit.truncated", None)
        return obs, rewards, dones, infos


def load_config(path: str | Path | None = None) -> dict[str, Any]:
    """Read a training config (default: the shipped ``agents/ppo.toml``)."""
    if path is None:
        text = resources.files("orbit_env.agents").joinpath(DEFAULT_CONFIG).read_text()
    else:
        text = Path(path).read_text()
    config = tomllib.loads(text)
    for key in ("env_id", "seed", "num_envs", "total_timesteps", "ppo", "policy"):
        if key not in config:
            raise ValueError(f"training config {path or DEFAULT_CONFIG} lacks the key {key!r}")
    schedule = config.get("learning_rate_schedule", "constant")
    if schedule not in ("constant", "linear"):
        raise ValueError(f"learning_rate_schedule={schedule!r} is invalid; allowed: constant, linear")
    decay_start = config.get("learning_rate_decay_start", 0.0)
    if not (isinstance(decay_start, (int, float)) and 0.0 <= decay_start < 1.0):
        raise ValueError(f"learning_rate_decay_start={decay_start!r} is invalid; allowed: a fraction in [0, 1)")
    shaping = config.get("shaping", "none")
    if shaping not in SHAPINGS:
        raise ValueError(f"shaping={shaping!r} is invalid; allowed: {', '.join(SHAPINGS)}")
    end_decided = config.get("end_decided", 0.0)
    if not (isinstance(end_decided, (int, float)) and 0.0 <= end_decided <= 1.0):
        raise ValueError(f"end_decided={end_decided!r} is invalid; allowed: a probability in [0, 1]")
    if end_decided > 0.0 and shaping != "never_burn_value":
        raise ValueError('end_decided > 0 needs shaping = "never_burn_value" (it ends episodes on its potential)')
    if int(config["total_timesteps"]) <= 0 or int(config["num_envs"]) <= 0:
        raise ValueError("total_timesteps and num_envs must be positive integers")
    return config


def linear_decay(rate: float, start: float = 0.0) -> Callable[[float], float]:
    """Learning rate ``rate`` until the fraction ``start`` of the run, then linearly down to 0 at its end.

    SB3 calls the schedule with the progress left, from 1 down to 0.
    """
    left_at_start = 1.0 - start
    return lambda progress_left: rate * min(1.0, progress_left / left_at_start)


def train(
    config_path: str | Path | None = None,
    out_dir: str | Path = "runs/ppo",
    *,
    total_timesteps: int | None = None,
    progress: bool = True,
) -> TrainResult:
    """Train PPO as the config says; return where the model went.

    Args:
        config_path: TOML file of hyperparameters (default: the shipped one).
        out_dir: Folder for ``model.zip``, ``checkpoints/`` and ``tensorboard/``.
        total_timesteps: Override the config's budget (smoke tests use a tiny one).
        progress: Show SB3's progress bar.
    """
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import CheckpointCallback
        from stable_baselines3.common.vec_env import VecNormalize
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError("training needs stable-baselines3 and torch: pip install 'orbit-env[train]'") from error

    import orbit_env  # noqa: F401  (registers the environments)
    from orbit_env.envs.sb3 import make_sb3_vec_env

    config = load_config(config_path)
    timesteps = int(total_timesteps if total_timesteps is not None else config["total_timesteps"])
    if timesteps <= 0:
        raise ValueError(f"total_timesteps must be positive, got {timesteps}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)  # small networks: threads cost more than they give on 2 cores
    seed = int(config["seed"])
    venv: Any = make_sb3_vec_env(config["env_id"], num_envs=int(config["num_envs"]), seed=seed)
    if not config.get("bootstrap_at_horizon", True):
        venv = MissionEndIsTerminal(venv)
    if config.get("shaping", "none") == "never_burn_value":
        from orbit_env.agents.shaping import never_burn_value_shaping

        # Before VecNormalize: it scales the shaped reward.
        venv = never_burn_value_shaping(venv, end_decided=float(config.get("end_decided", 0.0)), seed=seed)
    if config.get("normalize", {}).get("reward", False):
        venv = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=float(config["ppo"]["gamma"]))
    activation = {"tanh": torch.nn.Tanh, "relu": torch.nn.ReLU}[config["policy"].get("activation", "tanh")]
    policy_kwargs: dict[str, Any] = {"net_arch": list(config["policy"]["net_arch"]), "activation_fn": activation}
    if config["policy"].get("log_features", False):
        from orbit_env.agents.features import LogFeatures

        policy_kwargs["features_extractor_class"] = LogFeatures
    ppo_kwargs = dict(config["ppo"])
    if config.get("learning_rate_schedule", "constant") == "linear":
        ppo_kwargs["learning_rate"] = linear_decay(
            float(ppo_kwargs["learning_rate"]), float(config.get("learning_rate_decay_start", 0.0))
        )
    model = PPO(
        "MlpPolicy",
        venv,
        seed=seed,
        verbose=0,
        device="cpu",
        tensorboard_log=str(out / "tensorboard"),
        policy_kwargs=policy_kwargs,
        **ppo_kwargs,
    )
    coast_logit = float(config["policy"].get("initial_coast_logit", 0.0))
    if coast_logit:
        # Burns are rare decisions: a uniform initial policy burns a third of the time and
        # empties the tank in days, so it never learns what keeping propellant is worth.
        with torch.no_grad():
            model.policy.action_net.bias[0] += coast_logit
    callbacks = []
    every = int(config.get("checkpoint_every", 0))
    if every > 0:
        callbacks.append(
            CheckpointCallback(save_freq=max(every // int(config["num_envs"]), 1), save_path=str(out / "checkpoints"))
        )
    start = time.perf_counter()
    model.learn(total_timesteps=timesteps, callback=callbacks, progress_bar=progress, tb_log_name="ppo")
    seconds = time.perf_counter() - start
    model_path = out / "model.zip"
    model.save(model_path, exclude=["env", "tensorboard_log"])
    return TrainResult(model_path=model_path, log_dir=out / "tensorboard", seconds=seconds, timesteps=timesteps)
