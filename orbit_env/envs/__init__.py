"""Gymnasium environments: perigee burns against drag, registered in one place.

| id                            | actions                | density                                   |
|-------------------------------|------------------------|-------------------------------------------|
| ``OrbitRaising-v0``           | Discrete: burn sizes   | the paper's, known                        |
| ``OrbitRaisingContinuous-v0`` | Box [-1, 1]: burn size | the paper's, known                        |
| ``OrbitRaisingUncertain-v0``  | Discrete: burn sizes   | scale drawn per episode, hidden, drifting |
| ``OrbitRaisingSolar-v0``      | Discrete: burn sizes   | NRLMSIS under the real Sun; disposal rule |
| ``OrbitRaisingSolarContinuous-v0`` | Box [-1, 1]: burn size | the solar task's, with any burn size |

Each has a single environment (``gymnasium.make``) and a numpy-batched vector
environment (``gymnasium.make_vec(id, num_envs=N)``, autoreset ``NEXT_STEP`` by default);
`orbit_env.envs.sb3` hands the latter to Stable-Baselines3. The user's manual
is the docstring of `OrbitRaisingEnv` (of `OrbitRaisingSolarEnv` for the solar task).

**The mission's end is terminal.** An episode ends with ``terminated=True`` at re-entry and at
the mission's last step alike, and ``truncated`` is never set: the mission's length is part of
the task (the reward counts days within it, the solar task charges its disposal there, and the
observation holds the clock), not a time limit outside it, so an agent must not add the value
of a state after it (Pardo et al. 2018, "Time limits in reinforcement learning", ICML;
Gymnasium's ``TimeLimit``: truncation is for limits outside the MDP). ``info["reentered"]``
tells the two ends apart.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from orbit_env.envs.config import UNCERTAIN_DENSITY, DensityConfig, OrbitRaisingConfig

if TYPE_CHECKING:
    from orbit_env.envs.orbit_raising import OrbitRaisingEnv
    from orbit_env.envs.solar import OrbitRaisingSolarEnv

__all__ = [
    "DISPOSAL_YEARS",
    "ENV_IDS",
    "SOLAR_CONTINUOUS_ENV_ID",
    "SOLAR_ENV_ID",
    "SOLAR_ENV_IDS",
    "SOLAR_EVAL_SPLIT",
    "SOLAR_SPLITS",
    "DensityConfig",
    "OrbitRaisingConfig",
    "OrbitRaisingEnv",
    "OrbitRaisingSolarEnv",
    "register_envs",
]

#: What a single environment warns when stepped after its episode ended (as CartPole-v1 warns): call reset().
ENDED_WARNING = (
    "step() called after the episode ended (terminated=True): the satellite re-entered or the mission is over, "
    "and what a step returns now means nothing; call reset()"
)

_ENTRY_POINT = "orbit_env.envs.orbit_raising:OrbitRaisingEnv"
_VECTOR_ENTRY_POINT = "orbit_env.envs.vector:OrbitRaisingVectorEnv"

#: Every registered id and the keyword arguments that make the variant.
_VARIANTS: dict[str, dict[str, object]] = {
    "OrbitRaising-v0": {},
    "OrbitRaisingContinuous-v0": {"continuous": True},
    "OrbitRaisingUncertain-v0": {"density": UNCERTAIN_DENSITY},
}
#: The solar decision task's id (its own task model, `orbit_env.envs.solar_task`), and its continuous twin's.
SOLAR_ENV_ID = "OrbitRaisingSolar-v0"
SOLAR_CONTINUOUS_ENV_ID = "OrbitRaisingSolarContinuous-v0"
#: The ids of the solar task, and the keywords that make each.
_SOLAR_VARIANTS: dict[str, dict[str, object]] = {SOLAR_ENV_ID: {}, SOLAR_CONTINUOUS_ENV_ID: {"continuous": True}}
SOLAR_ENV_IDS = tuple(_SOLAR_VARIANTS)
#: The solar task's splits of the record (`orbit_env.envs.solar_task.SPLIT_DATE`): training's and the held-out one.
SOLAR_SPLITS = ("train", "test")
#: The split the solar task's yardsticks score on unless told otherwise (``orbit-env evaluate``, the sweep, the
#: certificate): the held-out cycles.
SOLAR_EVAL_SPLIT = "test"
#: The solar task's disposal rule unless told otherwise [years after the mission's end]: the FCC's 2022 rule for LEO.
DISPOSAL_YEARS = 5.0
_SOLAR_ENTRY_POINTS = ("orbit_env.envs.solar:OrbitRaisingSolarEnv", "orbit_env.envs.solar:OrbitRaisingSolarVectorEnv")
#: The ids of the known-density family (one task model, `orbit_env.envs.task`).
ENV_IDS = tuple(_VARIANTS)


def register_envs() -> None:
    """Register the orbit-raising environments with Gymnasium (safe to call twice).

    No ``max_episode_steps``: the environments end their missions themselves after
    ``horizon_steps`` (a flat keyword of ``gymnasium.make``), the one owner of the
    mission's length and of the observed clock.
    """
    import gymnasium

    entry_points = {env_id: (_ENTRY_POINT, _VECTOR_ENTRY_POINT) for env_id in _VARIANTS}
    entry_points.update({env_id: _SOLAR_ENTRY_POINTS for env_id in SOLAR_ENV_IDS})
    for env_id, (entry_point, vector_entry_point) in entry_points.items():
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point=entry_point,
            vector_entry_point=vector_entry_point,
            kwargs=dict({**_VARIANTS, **_SOLAR_VARIANTS}[env_id]),
        )


def __getattr__(name: str) -> Any:
    """The environment classes, imported when first asked for: registering the ids needs only their names.

    ``import orbit_env`` registers the ids for a command that decays one orbit as well; the
    classes (and the task models, the compiled kernels' modules) load on ``gymnasium.make``.
    """
    if name == "OrbitRaisingEnv":
        from orbit_env.envs.orbit_raising import OrbitRaisingEnv

        return OrbitRaisingEnv
    if name == "OrbitRaisingSolarEnv":
        from orbit_env.envs.solar import OrbitRaisingSolarEnv

        return OrbitRaisingSolarEnv
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
