"""Baselines across algorithms and seeds as Ray Tune trials (``orbit-env sweep``).

Each trial trains one Stable-Baselines3 algorithm with one seed on the numpy vector
environment, saves the model and scores it on the evaluation episodes of
``orbit-env evaluate`` (the plain reward; capture against the DP optimum, as there). On
``OrbitRaisingSolar-v0`` that is the solar evaluation (`orbit_env.agents.solar.evaluate_solar`):
trained on the train split, scored on the missions of the held-out test split, the capture
between never burning and the per-episode DP.
The trials run on Ray Tune (``pip install 'orbit-env[cluster]'``): a local Ray by
default, a cluster by its address. A sweep interrupted in the middle continues where
it stopped when run again with the same ``--out`` (finished trials are kept).

Algorithms: ``ppo``, ``a2c``, ``dqn`` (discrete actions), ``sac``, ``td3`` (continuous)
with Stable-Baselines3's defaults, and ``ppo_recipe``, the project's recipe (the TOML
file of the shipped agent of the environment, `orbit_env.agents.train`).

The table reports, per algorithm, rliable's interquartile mean (IQM) of the capture
over the seeds, with a 95% bootstrap confidence interval (seeds resampled with
replacement, the stratified bootstrap of rliable for one task), and the mean optimality
gap 1 - capture.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.envs import SOLAR_ENV_ID, SOLAR_EVAL_SPLIT

#: The algorithms a sweep runs, and the action spaces each takes.
SWEEP_ALGOS = {
    "ppo": ("discrete", "continuous"),
    "a2c": ("discrete", "continuous"),
    "dqn": ("discrete",),
    "sac": ("continuous",),
    "td3": ("continuous",),
    "ppo_recipe": ("discrete", "continuous"),
}
#: The recipe (training config) of each environment's shipped agent.
RECIPES = {
    "OrbitRaising-v0": "ppo.toml",
    "OrbitRaisingUncertain-v0": "ppo_uncertain.toml",
    "OrbitRaisingContinuous-v0": "ppo_continuous.toml",
    "OrbitRaisingSolar-v0": "ppo_solar.toml",
}
#: Satellites stepped together in a trial with SB3's defaults.
SWEEP_NUM_ENVS = 16
#: Bootstrap resamples of the confidence intervals.
BOOTSTRAP_SAMPLES = 2000


class SweepInterrupted(RuntimeError):
    """The sweep stopped before every trial finished; the same call resumes it."""


def iqm(values: NDArray[np.float64]) -> float:
    """Interquartile mean: the mean of the middle half (rliable's IQM; the mean for fewer than 4 values)."""
    x = np.sort(np.asarray(values, dtype=np.float64))
    n = x.size
    if n < 4:
        return float(x.mean())
    cut = n // 4
    return float(x[cut : n - cut].mean())


def bootstrap_interval(values: NDArray[np.float64], seed: int = 0, level: float = 0.95) -> tuple[float, float]:
    """A ``level`` bootstrap confidence interval of the IQM, the runs resampled with replacement."""
    x = np.asarray(values, dtype=np.float64)
    rng = np.random.default_rng(seed)
    draws = np.array([iqm(x[rng.integers(0, x.size, x.size)]) for _ in range(BOOTSTRAP_SAMPLES)])
    tail = (1.0 - level) / 2.0
    return float(np.quantile(draws, tail)), float(np.quantile(draws, 1.0 - tail))


def table(trials: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per algorithm: IQM of the capture with its 95% interval, the optimality gap, the returns."""
    rows = []
    for algo in dict.fromkeys(t["algo"] for t in trials):
        mine = [t for t in trials if t["algo"] == algo]
        returns = np.array([t["mean_return"] for t in mine])
        row: dict[str, Any] = {
            "algo": algo,
            "seeds": len(mine),
            "mean_return": float(returns.mean()),
            "iqm_return": iqm(returns),
            "wall_s": float(sum(t["wall_s"] for t in mine)),
        }
        captures = [t["capture"] for t in mine]
        if all(c is not None for c in captures):
            c = np.array(captures)
            low, high = bootstrap_interval(c)
            row.update({"iqm_capture": iqm(c), "capture_ci95": [low, high], "optimality_gap": float(1.0 - c.mean())})
        rows.append(row)
    return rows


def format_table(env_id: str, rows: list[dict[str, Any]], timesteps: int) -> str:
    """The table for people."""
    lines = [
        f"{env_id}: {timesteps} timesteps per trial; capture = (R - R_never) / (R_dp - R_never)",
        f"{'algo':<11} {'seeds':>5} {'IQM capture':>12} {'95% CI':>17} {'gap':>7} {'mean return':>12} {'wall [s]':>9}",
    ]
    for r in rows:
        if "iqm_capture" in r:
            ci = f"[{r['capture_ci95'][0]:6.1%}, {r['capture_ci95'][1]:6.1%}]"
            capture, gap = f"{r['iqm_capture']:12.1%}", f"{r['optimality_gap']:7.1%}"
        else:
            ci, capture, gap = "", "", ""
        lines.append(
            f"{r['algo']:<11} {r['seeds']:>5} {capture:>12} {ci:>17} {gap:>7} {r['mean_return']:12.2f} "
            f"{r['wall_s']:9.0f}"
        )
    return "\n".join(lines)


def train_trial(
    env_id: str,
    algo: str,
    seed: int,
    timesteps: int,
    out_dir: str | Path,
    num_envs: int = SWEEP_NUM_ENVS,
    *,
    callbacks: Sequence[Any] = (),
) -> Path:
    """Train one algorithm with one seed; return where its model went.

    ``callbacks``: SB3 callbacks that see the training (`orbit_env.agents.curves` scores the policy with one).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if algo == "ppo_recipe":
        from orbit_env.agents.train import train

        config = resources.files("orbit_env.agents").joinpath(RECIPES[env_id])
        result = train(
            config, out, total_timesteps=timesteps, seed=seed, progress=False, force=True, extra_callbacks=callbacks
        )
        return result.model_path
    import stable_baselines3
    import torch

    from orbit_env.agents.train import BootstrapAtHorizon
    from orbit_env.envs.sb3 import make_sb3_vec_env

    torch.set_num_threads(1)
    # Monitored (SB3's episode statistics). The defaults' rows of the published tables were trained when the
    # environments reported the mission's end as a time limit, which SB3 bootstraps past: kept so, so that a
    # sweep run again reproduces them (the recipe's config says bootstrap_at_horizon = false).
    venv = BootstrapAtHorizon(make_sb3_vec_env(env_id, num_envs=num_envs, seed=seed))
    model = getattr(stable_baselines3, algo.upper())("MlpPolicy", venv, seed=seed, device="cpu", verbose=0)
    model.learn(total_timesteps=timesteps, callback=list(callbacks) or None)
    model.orbit_env = {"env_id": env_id, "env": {}}
    path = out / "model.zip"
    model.save(path, exclude=["env", "tensorboard_log"])
    return path


def score_model(env_id: str, model: Any, episodes: int, eval_seed: int) -> float:
    """A model's mean return on the evaluation episodes, deterministic actions, as ``orbit-env evaluate`` scores it.

    The solar task flies the missions of the held-out `SOLAR_EVAL_SPLIT` (`orbit_env.agents.solar.fly_model`).
    """
    if env_id == SOLAR_ENV_ID:
        from orbit_env.agents.solar import fly_model

        return float(fly_model(model, episodes, eval_seed, {"solar_split": SOLAR_EVAL_SPLIT}).returns.mean())
    from orbit_env.agents.evaluate import run_episodes

    return float(run_episodes(env_id, model, episodes, eval_seed).returns.mean())


def capture_of(mean_return: float, references: dict[str, Any]) -> float | None:
    """`orbit_env.agents.evaluate.capture` against a sweep's ``never_return`` and ``dp_return``."""
    from orbit_env.agents.evaluate import capture

    return capture(mean_return, references.get("never_return"), references.get("dp_return"))


def run_trial(config: dict[str, Any]) -> dict[str, Any]:
    """One trial (Ray Tune's function trainable): train, then score on the evaluation episodes (`score_model`)."""
    from orbit_env.agents.evaluate import load_model

    start = time.perf_counter()
    env_id = config["env_id"]
    trial_dir = Path(config["out"]) / "trials" / f"{config['algo']}_seed{config['seed']}"
    path = train_trial(env_id, config["algo"], int(config["seed"]), int(config["timesteps"]), trial_dir)
    _, model = load_model(env_id, path)
    mean = score_model(env_id, model, int(config["episodes"]), int(config["eval_seed"]))
    return {
        "algo": config["algo"],
        "seed": int(config["seed"]),
        "mean_return": mean,
        "capture": capture_of(mean, config),
        "wall_s": time.perf_counter() - start,
        "model": str(path),
    }


def capture_references(
    env_id: str, episodes: int, eval_seed: int, include_dp: bool = True, *, workers: int | None = None
) -> dict[str, Any]:
    """The mean returns the capture is measured between: never burning, and the DP (None without it).

    On the solar task, the rows ``never`` and ``dp`` of `orbit_env.agents.solar.evaluate_solar` on
    the `SOLAR_EVAL_SPLIT` (``workers``: its processes solving the DPs; default: the cores).
    """
    from orbit_env.agents.evaluate import dp_policy, hand_coded_policies, run_episodes

    if env_id == SOLAR_ENV_ID:
        from orbit_env.agents.solar import evaluate_solar

        flown = evaluate_solar(
            episodes, eval_seed, solar_split=SOLAR_EVAL_SPLIT, include_dp=include_dp, workers=workers
        ).flown
        dp = flown.get("dp")
        return {
            "never_return": float(flown["never"].returns.mean()),
            "dp_return": None if dp is None else float(dp.returns.mean()),
        }
    never = run_episodes(env_id, hand_coded_policies(env_id)["never"], episodes, eval_seed).returns.mean()
    references: dict[str, Any] = {"never_return": float(never), "dp_return": None}
    if include_dp:
        references["dp_return"] = float(run_episodes(env_id, dp_policy(env_id), episodes, eval_seed).returns.mean())
    return references


def finished_trials(results: list[Any], out: Path) -> list[dict[str, Any]]:
    """The table's entries of Tune's results (each with ``.error`` and ``.metrics``).

    Raises:
        RuntimeError: a trial failed (its error).
        SweepInterrupted: the sweep stopped (Ctrl-C, a time limit) before some trials
            reported; Tune has kept the finished ones, and the same call resumes.
    """
    for result in results:
        if result.error is not None:
            raise RuntimeError(f"a trial failed: {result.error}")
    unfinished = sum("mean_return" not in (result.metrics or {}) for result in results)
    if unfinished:
        raise SweepInterrupted(
            f"the sweep stopped with {unfinished} of {len(results)} trials unfinished; "
            f"run the same command again to resume it ({out})"
        )
    return [{key: r.metrics[key] for key in ("algo", "seed", "mean_return", "capture", "wall_s")} for r in results]


def _progress_callback(tune: Any, total: int, say: Callable[[str], None]) -> Any:
    """A Ray Tune callback that reports each finished trial through ``say`` (Tune itself is kept quiet)."""

    class Progress(tune.Callback):  # type: ignore[misc, name-defined]
        def on_trial_complete(self, iteration: int, trials: list[Any], trial: Any, **info: Any) -> None:
            done = sum(t is trial or t.status == "TERMINATED" for t in trials)  # this one is not marked yet
            result = trial.last_result or {}
            capture = result.get("capture")
            score = "" if capture is None else f", capture {100 * capture:.1f}%"
            say(
                f"trial {done}/{total} done: {result.get('algo')} seed {result.get('seed')}, "
                f"mean return {result.get('mean_return', float('nan')):.2f}{score}, {result.get('wall_s', 0.0):.0f} s"
            )

    return Progress()


def starts_ray(address: str | None) -> bool:
    """Whether ``ray.init(address)`` starts a Ray of its own, whose CPUs a sweep may set.

    ``"local"`` starts a new one; None starts one unless a Ray runs already on this machine (Ray then
    refuses the CPUs itself); any other address joins a running Ray.
    """
    return address in (None, "local")


def _ray_trainable(config: dict[str, Any]) -> None:
    from ray import tune

    tune.report(run_trial(config))


def sweep(
    env_id: str,
    algos: list[str],
    seeds: int,
    timesteps: int,
    out_dir: str | Path,
    *,
    address: str | None = None,
    episodes: int = 1000,
    eval_seed: int | None = None,
    include_dp: bool = True,
    cpus_per_trial: float = 1.0,
    cpus: int | None = None,
    workers: int | None = None,
    progress: Any = None,
) -> dict[str, Any]:
    """Run the trials on Ray Tune, write ``out_dir/results.json``, return its content (see the module).

    ``cpus``: the CPUs of the Ray the sweep starts (`starts_ray`; default: the cores), so at most
    ``cpus / cpus_per_trial`` trials run at once. ``workers``: the solar task's processes
    solving the references' DPs (`capture_references`).

    Raises:
        ValueError: an unknown env or algorithm, one that does not fit the action space or is given twice, counts
            below 1, or an OUT folder that holds a sweep of other settings.
        ImportError: Ray is not installed (the ``cluster`` extra).
    """
    import gymnasium

    from orbit_env.agents.evaluate import EVAL_SEED
    from orbit_env.envs import ENV_IDS

    allowed = (*ENV_IDS, SOLAR_ENV_ID)
    if env_id not in allowed:
        raise ValueError(f"unknown environment {env_id!r}; allowed: {', '.join(allowed)}")
    base = gymnasium.make(env_id).unwrapped  # its action space (the solar task has no task_of)
    kind = "discrete" if isinstance(base.action_space, gymnasium.spaces.Discrete) else "continuous"
    for algo in algos:
        if algo not in SWEEP_ALGOS:
            raise ValueError(f"unknown algorithm {algo!r}; allowed: {', '.join(SWEEP_ALGOS)}")
        if kind not in SWEEP_ALGOS[algo]:
            raise ValueError(f"{algo} does not act in the {kind} action space of {env_id}")
    repeated = sorted({algo for algo in algos if list(algos).count(algo) > 1})
    if repeated:
        raise ValueError(f"algorithms {', '.join(repeated)} given twice: each is one row of seeds")
    if seeds < 1 or timesteps < 1 or episodes < 1:
        raise ValueError("seeds, timesteps and episodes must be >= 1")
    if cpus is not None and cpus < 1:
        raise ValueError(f"cpus={cpus} is invalid; allowed: an integer >= 1")
    if cpus is not None and not starts_ray(address):
        raise ValueError(
            f"cpus={cpus} sets the CPUs of a Ray the sweep starts (address None or 'local'); address={address!r} "
            "joins a running Ray, which has its own: leave cpus out"
        )
    try:
        import ray
        from ray import tune
    except ImportError as error:
        raise ImportError("orbit-env sweep runs on Ray Tune: pip install 'orbit-env[cluster]'") from error
    say = progress or (lambda text: None)
    eval_seed = EVAL_SEED if eval_seed is None else eval_seed
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)
    # A folder resumes its own sweep only: Ray restores the trials it was given, whatever is asked now.
    settings = {
        "env": env_id,
        "algos": list(algos),
        "seeds": int(seeds),
        "timesteps": int(timesteps),
        "episodes": int(episodes),
        "eval_seed": int(eval_seed),
        "dp": bool(include_dp),
    }
    settings_path = out / "settings.json"
    if settings_path.is_file():
        kept = json.loads(settings_path.read_text())
        if kept != settings:
            raise ValueError(f"{out} holds a sweep of other settings ({kept}); give another --out to run this one")
    elif (out / "ray" / "sweep").exists():  # a sweep from before the settings were recorded: whose, unknown
        raise ValueError(
            f"{out} holds a sweep that does not record its settings; to resume it as it was started, write them "
            f"to {settings_path} (these would be {json.dumps(settings)}), or give another --out"
        )
    else:
        settings_path.write_text(json.dumps(settings) + "\n")
    # The references of the capture, once for all trials (the DP's solve is the heavy part).
    references_path = out / "references.json"
    if references_path.is_file():
        references = json.loads(references_path.read_text())
    else:
        say("references: never" + (" and dp" if include_dp else ""))
        references = capture_references(env_id, episodes, eval_seed, include_dp, workers=workers)
        references_path.write_text(json.dumps(references) + "\n")
    split = {"solar_split": SOLAR_EVAL_SPLIT} if env_id == SOLAR_ENV_ID else {}
    param_space = {
        "env_id": env_id,
        "algo": tune.grid_search(list(algos)),
        "seed": tune.grid_search(list(range(seeds))),
        "timesteps": int(timesteps),
        "episodes": int(episodes),
        "eval_seed": int(eval_seed),
        "out": str(out),
        **split,
        **references,
    }
    start = time.perf_counter()
    ray.init(address=address, num_cpus=cpus, include_dashboard=False, log_to_driver=False, ignore_reinit_error=True)
    try:
        trainable = tune.with_resources(_ray_trainable, {"cpu": cpus_per_trial})
        storage = out / "ray"
        if tune.Tuner.can_restore(str(storage / "sweep")):
            say("resuming the sweep in " + str(storage / "sweep"))
            tuner = tune.Tuner.restore(str(storage / "sweep"), trainable, resume_errored=True)
        else:
            tuner = tune.Tuner(
                trainable,
                param_space=param_space,
                run_config=tune.RunConfig(
                    name="sweep",
                    storage_path=str(storage),
                    verbose=0,
                    callbacks=[_progress_callback(tune, len(algos) * seeds, say)],
                ),
            )
        grid = tuner.fit()
        cores = int(ray.cluster_resources().get("CPU", 0))
    finally:
        ray.shutdown()
    trials = finished_trials(list(grid), out)
    trials.sort(key=lambda t: (list(algos).index(t["algo"]), t["seed"]))
    output = {
        "env": env_id,
        "timesteps": int(timesteps),
        "episodes": int(episodes),
        "eval_seed": int(eval_seed),
        **split,
        **references,
        "trials": trials,
        "table": table(trials),
        "sweep_wall_s": time.perf_counter() - start,
        "cores": cores,
    }
    (out / "results.json").write_text(json.dumps(output, indent=1) + "\n")
    return output
