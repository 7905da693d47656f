"""Learning curves, the benchmark's protocol as code (``orbit-env curves``).

The capture (``orbit-env evaluate``'s metric: (R - R_never) / (R_dp - R_never), the mean
return of deterministic actions on the plain reward) against environment steps, for
Stable-Baselines3's PPO with its defaults (``ppo``) and the project's recipe
(``ppo_recipe``: the TOML of the environment's shipped agent), over seeds 0 to n - 1,
aggregated as rliable does for one task: at every point the interquartile mean (IQM)
over the seeds with a 95% bootstrap confidence interval (`orbit_env.agents.sweep.iqm`,
`orbit_env.agents.sweep.bootstrap_interval`).

The protocol is fixed so that anyone's numbers compare:

* evaluation starts: those of ``orbit-env evaluate`` (`orbit_env.agents.evaluate.EVAL_SEED`,
  ``--episodes``, default `orbit_env.agents.evaluate.EVAL_EPISODES`); the solar task's
  held-out test split, as ``evaluate`` scores it;
* the references (never burning, the DP) on the same starts, computed once per output folder;
* a point before the first update (step 0), every ``every`` steps (at the first rollout
  boundary past it) and at the end.

Every run trains in its own process (``--workers``) and writes its curve to
``OUT/curves/ALGO_seedS.json`` when it ends; the same command skips the runs already
written, so a sweep cut short resumes by run. ``OUT/results.json`` holds the runs and the
aggregated curves, ``--plot`` draws them.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from concurrent.futures import as_completed
from pathlib import Path
from typing import Any

import numpy as np

from orbit_env.agents.sweep import bootstrap_interval, capture_of, iqm, score_model, train_trial
from orbit_env.analysis.catalogue_io import atomic_text
from orbit_env.workers import spawned_pool

#: The algorithms of the curves: SB3's PPO with its defaults, and the project's recipe.
CURVE_ALGOS = ("ppo", "ppo_recipe")


def run_curve(
    env_id: str,
    algo: str,
    seed: int,
    timesteps: int,
    every: int,
    episodes: int,
    eval_seed: int,
    references: dict[str, Any],
    out_dir: str | Path,
) -> dict[str, Any]:
    """Train one run and score it at its points; write and return ``{"algo", "seed", "points", "wall_s"}``.

    ``points``: ``[timesteps, mean return, capture]`` at step 0, every ``every`` steps and at the end; the
    capture None (JSON null) where it is undefined (never burning as good as the DP on the episodes).
    """
    from stable_baselines3.common.callbacks import BaseCallback

    points: list[list[float | None]] = []

    def score(model: Any, steps: int) -> None:
        mean = score_model(env_id, model, episodes, eval_seed)
        capture = capture_of(mean, references)
        points.append([float(steps), mean, capture])

    class CaptureCurve(BaseCallback):  # type: ignore[misc]
        """Scores the policy being trained at its points (see `run_curve`).

        At the start of a rollout: the policy has then been updated on every step counted.
        """

        def __init__(self) -> None:
            super().__init__()
            self.next_at = 0

        def _on_rollout_start(self) -> None:
            if self.num_timesteps >= self.next_at:
                score(self.model, self.num_timesteps)
                self.next_at = (self.num_timesteps // every + 1) * every

        def _on_step(self) -> bool:
            return True

        def _on_training_end(self) -> None:  # after the last update
            if not points or points[-1][0] < self.num_timesteps:
                score(self.model, self.num_timesteps)

    start = time.perf_counter()
    out = Path(out_dir)
    train_trial(env_id, algo, seed, timesteps, out / "runs" / f"{algo}_seed{seed}", callbacks=[CaptureCurve()])
    run = {"algo": algo, "seed": seed, "points": points, "wall_s": time.perf_counter() - start}
    path = out / "curves" / f"{algo}_seed{seed}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_text(path) as handle:  # whole or not at all: a cut run is run again
        handle.write(json.dumps(run) + "\n")
    return run


def _run_curve(job: tuple[Any, ...]) -> dict[str, Any]:
    return run_curve(*job)


def aggregate(runs: Sequence[dict[str, Any]]) -> dict[str, dict[str, list[float | None]]]:
    """Per algorithm, at each point all its runs reached: the IQM of the capture over seeds and its 95% CI.

    The runs of an algorithm share their points up to the rollout size (the same
    ``every`` and hyperparameters); each point's step is the seeds' median. A point where a
    run's capture is undefined (None) has none of the three (None, JSON null).
    """
    curves: dict[str, dict[str, list[float | None]]] = {}
    for algo in dict.fromkeys(run["algo"] for run in runs):
        # None (and NaN, in a file written before the captures were null) reads as NaN.
        mine = [np.asarray(run["points"], dtype=np.float64) for run in runs if run["algo"] == algo]
        count = min(len(points) for points in mine)
        steps = np.median([points[:count, 0] for points in mine], axis=0)
        captures = np.array([points[:count, 2] for points in mine])  # (seeds, points)
        defined = np.isfinite(captures).all(axis=0)
        intervals = [bootstrap_interval(captures[:, k]) if defined[k] else (None, None) for k in range(count)]
        curves[algo] = {
            "timesteps": steps.tolist(),
            "iqm_capture": [iqm(captures[:, k]) if defined[k] else None for k in range(count)],
            "ci95_low": [low for low, _ in intervals],
            "ci95_high": [high for _, high in intervals],
            "seeds": [float(len(mine))] * count,
        }
    return curves


def curves(
    env_id: str,
    algos: Sequence[str],
    seeds: int,
    timesteps: int,
    every: int,
    out_dir: str | Path,
    *,
    episodes: int | None = None,
    workers: int = 1,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run (or resume) every algorithm x seed, write ``OUT/results.json`` and return it (see the module).

    Raises:
        ValueError: an algorithm outside `CURVE_ALGOS`, counts below 1, an unknown env.
    """
    from orbit_env.agents.evaluate import EVAL_EPISODES, EVAL_SEED, missing_learning_libraries
    from orbit_env.agents.sweep import RECIPES, capture_references
    from orbit_env.optional import TRAIN_EXTRA

    missing = missing_learning_libraries()
    if missing:  # before any work: the references take seconds, and each curve is a training run
        raise ImportError(f"learning curves need {' and '.join(missing)}: {TRAIN_EXTRA}")
    for algo in algos:
        if algo not in CURVE_ALGOS:
            raise ValueError(f"unknown algorithm {algo!r}; allowed: {', '.join(CURVE_ALGOS)}")
    repeated = sorted({algo for algo in algos if list(algos).count(algo) > 1})
    if repeated:
        raise ValueError(f"algorithms {', '.join(repeated)} given twice: each is one curve of seeds")
    if env_id not in RECIPES:
        raise ValueError(f"unknown environment {env_id!r}; allowed: {', '.join(RECIPES)}")
    if min(seeds, timesteps, every, workers) < 1 or (episodes is not None and episodes < 1):
        raise ValueError("seeds, timesteps, every, episodes and workers must be >= 1")
    say = progress or (lambda text: None)
    episodes = EVAL_EPISODES if episodes is None else episodes
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    settings = {"env": env_id, "timesteps": timesteps, "every": every, "episodes": episodes, "eval_seed": EVAL_SEED}
    settings_path = out / "settings.json"
    if settings_path.is_file():
        kept = json.loads(settings_path.read_text())
        if kept != settings:
            raise ValueError(f"{out} holds curves of other settings ({kept}); give another --out")
    else:
        settings_path.write_text(json.dumps(settings) + "\n")
    references_path = out / "references.json"
    if references_path.is_file():
        references = json.loads(references_path.read_text())
    else:
        say("references: never and dp on the evaluation starts")
        references = capture_references(env_id, episodes, EVAL_SEED)
        references_path.write_text(json.dumps(references) + "\n")
    start = time.perf_counter()
    done: list[dict[str, Any]] = []
    jobs = []
    for algo in algos:
        for seed in range(seeds):
            path = out / "curves" / f"{algo}_seed{seed}.json"
            if path.is_file():
                done.append(json.loads(path.read_text()))
            else:
                jobs.append((env_id, algo, seed, timesteps, every, episodes, EVAL_SEED, references, str(out)))
    if done:
        say(f"{len(done)} runs already written in {out / 'curves'}; {len(jobs)} to go")
    if workers > 1 and len(jobs) > 1:
        # Spawned workers, stopped at once if this process is interrupted (Ctrl-C, SIGTERM: a plain pool waited for
        # them to finish their runs); each run is reported as it ends, whatever its place in the list.
        with spawned_pool(min(workers, len(jobs))) as pool:
            for future in as_completed([pool.submit(_run_curve, job) for job in jobs]):
                done.append(future.result())
                say(_finished(done[-1], len(done), len(algos) * seeds))
    else:
        for job in jobs:
            done.append(_run_curve(job))
            say(_finished(done[-1], len(done), len(algos) * seeds))
    done.sort(key=lambda run: (list(algos).index(run["algo"]), run["seed"]))
    output = {
        **settings,
        **references,
        "runs": done,
        "curves": aggregate(done),
        "wall_s_this_call": time.perf_counter() - start,
    }
    (out / "results.json").write_text(json.dumps(output, indent=1) + "\n")
    return output


def _finished(run: dict[str, Any], count: int, total: int) -> str:
    steps, _, capture = run["points"][-1]
    score = f"capture {100 * capture:.1f}%" if capture is not None else "no capture (never burning is optimal)"
    return (
        f"run {count}/{total}: {run['algo']} seed {run['seed']}, {score} "
        f"after {steps:,.0f} steps, {run['wall_s']:.0f} s"
    )


def format_curves(result: dict[str, Any]) -> str:
    """The aggregated curves as a table for people: IQM capture [95% CI] per algorithm at each point."""
    lines = [
        f"{result['env']}: capture on {result['episodes']} evaluation episodes (seed {result['eval_seed']}), "
        f"IQM over seeds [95% bootstrap CI]"
    ]
    for algo, curve in result["curves"].items():
        lines.append(f"{algo} ({curve['seeds'][0]:.0f} seeds)")
        for steps, value, low, high in zip(
            curve["timesteps"], curve["iqm_capture"], curve["ci95_low"], curve["ci95_high"], strict=True
        ):
            if value is None:
                lines.append(f"  {steps:>12,.0f} steps  no capture (never burning is optimal on these episodes)")
            else:
                lines.append(f"  {steps:>12,.0f} steps  {100 * value:7.1f}%  [{100 * low:6.1f}%, {100 * high:6.1f}%]")
    return "\n".join(lines)


def plot_curves(result: dict[str, Any], path: str | Path) -> None:
    """Capture against steps: each algorithm's IQM with its 95% CI band, and each seed's run faintly."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.8))
    for k, (algo, curve) in enumerate(result["curves"].items()):
        color = f"C{k}"
        for run in result["runs"]:
            if run["algo"] == algo:
                points = np.asarray(run["points"], dtype=np.float64)  # an undefined capture: a gap
                ax.plot(points[:, 0], 100 * points[:, 2], color=color, alpha=0.25, linewidth=0.8)
        steps = np.asarray(curve["timesteps"])
        band = [100 * np.asarray(curve[key], dtype=np.float64) for key in ("ci95_low", "ci95_high", "iqm_capture")]
        ax.fill_between(steps, band[0], band[1], color=color, alpha=0.2)
        ax.plot(steps, band[2], color=color, linewidth=2, label=f"{algo}: IQM, 95% CI")
    ax.axhline(100.0, color="black", linewidth=0.8, linestyle=":")
    ax.axhline(0.0, color="grey", linewidth=0.8, linestyle=":")
    ax.set_xlabel("environment steps")
    ax.set_ylabel("capture of the DP's gain over never burning [%]")
    runs, episodes, seed = len(result["runs"]), result["episodes"], result["eval_seed"]
    ax.set_title(f"{result['env']}: {runs} runs, {episodes} evaluation episodes (seed {seed})")
    low, high = ax.get_ylim()
    ax.set_ylim(max(low, -100.0), max(high, 105.0))  # SB3's defaults can spend the tank: far below never
    ax.legend(loc="lower right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
