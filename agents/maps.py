"""Where each policy burns: maps over the (perigee, apogee) plane at a full tank.

``python -m orbit_env.agents.maps --out docs/burn_map.png`` draws the optimum (DP) beside PPO
and the greedy look-ahead at the start of a mission: for every start orbit, the burn
the policy asks for.
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from typing import Any

import gymnasium
import numpy as np

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.envs.config import OrbitRaisingConfig


def start_observations(
    env_id: str, perigee_km: np.ndarray, apogee_km: np.ndarray
) -> tuple[np.ndarray, OrbitRaisingConfig]:
    """The environment's first observation for each start orbit (full tank, clock 0)."""
    env = gymnasium.make_vec(env_id, num_envs=perigee_km.size, vectorization_mode="vector_entry_point")
    obs, _ = env.reset(seed=0, options={"perigee_km": perigee_km, "apogee_km": apogee_km})
    config = env.unwrapped.config
    env.close()
    return obs, config


def burn_map(
    env_id: str, policies: Mapping[str, Any], perigee_km: np.ndarray, apogee_km: np.ndarray
) -> dict[str, np.ndarray]:
    """The burn [m/s] each policy asks for at each (perigee, apogee) start (NaN where apogee < perigee)."""
    hp, ha = np.meshgrid(perigee_km, apogee_km, indexing="ij")
    valid = ha >= hp
    obs, config = start_observations(env_id, hp[valid], ha[valid])
    sizes = np.asarray(config.burn_sizes_m_s)
    maps = {}
    for name, policy in policies.items():
        actions, _ = policy.predict(obs, deterministic=True)
        grid = np.full(hp.shape, np.nan)
        grid[valid] = sizes[np.asarray(actions, dtype=np.intp)]
        maps[name] = grid
    return maps


def plot_burn_maps(
    maps: Mapping[str, np.ndarray], perigee_km: np.ndarray, apogee_km: np.ndarray, sizes: np.ndarray, path: str
) -> None:
    """Side-by-side maps of the first burn, one colour per burn size."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    from orbit_env.optional import pyplot

    plt = pyplot()
    colours = ListedColormap(plt.get_cmap("viridis")(np.linspace(0.0, 1.0, sizes.size)))
    edges = np.concatenate([[sizes[0] - 1.0], (sizes[1:] + sizes[:-1]) / 2, [sizes[-1] + 1.0]])
    norm = BoundaryNorm(edges, colours.N)
    fig, axes = plt.subplots(
        1, len(maps), figsize=(4.6 * len(maps) + 1.0, 4.4), dpi=120, sharey=True, layout="constrained"
    )
    axes = np.atleast_1d(axes)
    for ax, (name, grid) in zip(axes, maps.items(), strict=True):
        image = ax.pcolormesh(apogee_km, perigee_km, grid, cmap=colours, norm=norm, shading="nearest")
        ax.plot([perigee_km[0], perigee_km[-1]], [perigee_km[0], perigee_km[-1]], color="0.5", lw=0.8)
        ax.set_title(f"{name}: first burn at a full tank", fontsize=10)
        ax.set_xlabel("apogee height [km]")
    axes[0].set_ylabel("perigee height [km]")
    bar = fig.colorbar(image, ax=list(axes), ticks=sizes)
    bar.set_label("burn [m/s]")
    fig.savefig(path)
    plt.close(fig)


def main(argv: list[str] | None = None) -> None:
    """Draw the DP, PPO and greedy burn maps of ``OrbitRaising-v0``."""
    from orbit_env.agents.evaluate import dp_policy, hand_coded_policies, load_model, task_of

    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="burn_map.png")
    parser.add_argument("--env", default="OrbitRaising-v0")
    args = parser.parse_args(argv)
    perigee = np.linspace(160.0, 500.0, 69)
    apogee = np.linspace(160.0, 1600.0, 145)
    policies = {
        "dp (optimum)": dp_policy(args.env),
        "ppo": load_model(args.env)[1],
        "greedy": hand_coded_policies(args.env)["greedy"],
    }
    maps = burn_map(args.env, policies, perigee, apogee)
    sizes = np.asarray(task_of(args.env).config.burn_sizes_m_s)
    plot_burn_maps(maps, perigee, apogee, sizes, args.out)
    for name, grid in maps.items():
        print(
            f"{name}: burns at {np.nanmean(grid > 0):.0%} of start orbits, mean first burn {np.nanmean(grid):.1f} m/s"
        )


if __name__ == "__main__":
    main()
