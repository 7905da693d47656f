"""What a researcher reads from the environments on day one: spec, info, action clipping, headless checks.

Each test here pins one item of the interface as Gymnasium's own environments have it
(``spec.max_episode_steps``, LunarLander's clipped actions, ``check_env`` on a machine
without a display, outcome keys in ``info``).
"""

from __future__ import annotations

import copy
import pickle
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.wrappers import TimeLimit

from orbit_env.envs import ENV_IDS, SOLAR_ENV_ID, SOLAR_ENV_IDS, register_envs
from orbit_env.envs.config import DEFAULT_HORIZON_STEPS

if not all(env_id in gym.envs.registry for env_id in ENV_IDS):
    register_envs()

OUTLIVES = {"perigee_km": 500.0, "apogee_km": 1000.0}  # lives through any test's horizon


def wrappers(env: gym.Env) -> list[type]:
    """The classes of the wrappers around an environment, outermost first."""
    found = []
    while isinstance(env, gym.Wrapper):
        found.append(type(env))
        env = env.env
    return found


# --------------------------------------------------------------------------------------
# spec.max_episode_steps: the horizon, with the environment the one owner of the truncation
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_the_spec_reports_the_horizon_without_a_second_time_limit(env_id):
    env = gym.make(env_id)
    assert env.spec.max_episode_steps == DEFAULT_HORIZON_STEPS == 365
    assert TimeLimit not in wrappers(env)  # the environment ends its missions itself: one owner
    short = gym.make(env_id, horizon_steps=10)
    assert short.spec.max_episode_steps == 10  # follows the horizon keyword
    assert short.unwrapped.spec.max_episode_steps == 10
    short.reset(seed=0, options=OUTLIVES)
    # The mission's end is terminal (the satellite still up: info says it did not re-enter), never truncated.
    ends = [short.step(short.action_space.sample())[2:4] for _ in range(10)]
    assert ends == [(False, False)] * 9 + [(True, False)]
    # Made again from its spec (as check_env does): the same horizon and the same episode length (its
    # TimeLimit at the same step adds truncated to the step that terminates).
    again = gym.make(short.spec)
    assert again.spec.max_episode_steps == 10 and again.unwrapped.config.horizon_steps == 10
    again.reset(seed=0, options=OUTLIVES)
    ends = [again.step(again.action_space.sample())[2:4] for _ in range(10)]
    assert ends == [(False, False)] * 9 + [(True, True)]


# --------------------------------------------------------------------------------------
# Continuous actions outside [-1, 1] are clipped, as LunarLander's; NaN is refused
# --------------------------------------------------------------------------------------


def test_continuous_actions_outside_the_box_are_clipped_and_nan_refused():
    start = {"perigee_km": 300.0, "apogee_km": 600.0}
    for outside, inside in ((1.5, 1.0), (7.0, 1.0), (-3.0, -1.0)):
        clipped, plain = gym.make("OrbitRaisingContinuous-v0"), gym.make("OrbitRaisingContinuous-v0")
        clipped.reset(seed=0, options=start)
        plain.reset(seed=0, options=start)
        a = clipped.step(np.array([outside], dtype=np.float32))
        b = plain.step(np.array([inside], dtype=np.float32))
        np.testing.assert_array_equal(a[0], b[0])
        assert a[1:] == b[1:]
    assert a[4]["burn_m_s"] == 0.0  # -3 clips to -1: a coast
    assert b[4]["burn_m_s"] == 0.0
    env = gym.make("OrbitRaisingContinuous-v0").unwrapped
    env.reset(seed=0, options=start)
    assert env.step(2.0)[4]["burn_m_s"] == 100.0  # a plain number clips too
    with pytest.raises(ValueError, match=r"action=array\(\[nan\]"):
        env.step(np.array([np.nan], dtype=np.float32))
    vec = gym.make_vec("OrbitRaisingContinuous-v0", num_envs=3, vectorization_mode="vector_entry_point")
    vec.reset(seed=0, options=start)
    *_, info = vec.step(np.array([[2.0], [-5.0], [0.5]]))
    np.testing.assert_array_equal(info["burn_m_s"], [100.0, 0.0, 50.0])
    with pytest.raises(ValueError, match=r"action nan is invalid; allowed: numbers, not NaN \(clipped to \[-1, 1\]\)"):
        vec.step(np.array([[0.0], [np.nan], [0.0]]))


# --------------------------------------------------------------------------------------
# info: the episode's outcome so far at every step and reset, single and vector env
# --------------------------------------------------------------------------------------

OUTCOME = ("reentered", "days_in_orbit", "dv_used_m_s")
STARTS = [  # re-enters inside a 40-step horizon, and outlives it
    {"perigee_km": 170.0, "apogee_km": 300.0},
    {"perigee_km": 400.0, "apogee_km": 900.0},
]


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_info_holds_the_outcome_so_far_at_every_step(env_id):
    env = gym.make(env_id, horizon_steps=40)
    env.action_space.seed(0)  # the burns are drawn, but the same on every run
    for start in STARTS:
        _, info = env.reset(seed=0, options=start)
        assert info == {"reentered": False, "days_in_orbit": 0.0, "dv_used_m_s": 0.0}
        rewards, burns = 0.0, 0.0
        # drawn burns only on the start that outlives the horizon: a burn could save the low one
        burning = start is not STARTS[0]
        for k in range(40):
            action = env.action_space.sample() if k < 5 and burning else env.action_space.sample() * 0
            _, reward, terminated, truncated, info = env.step(action)
            assert set(info) == {"burn_m_s", *OUTCOME} and not truncated
            # Terminated at re-entry and at the mission's end; info tells which.
            assert type(info["reentered"]) is bool and info["reentered"] == (terminated and k < 39)
            rewards += reward
            burns += info["burn_m_s"]
            assert info["dv_used_m_s"] == pytest.approx(burns, abs=1e-9)
            # reward = days in orbit during the step - cost x burn
            assert info["days_in_orbit"] == pytest.approx(rewards + 0.4 * burns, abs=1e-9)
            assert info["days_in_orbit"] == env.unwrapped.state["time_days"]
            if terminated or truncated:
                break
        assert info["reentered"] == (start is STARTS[0])


def vector_and_singles(env_id, mode):
    vec = gym.make_vec(
        env_id, num_envs=2, vectorization_mode="vector_entry_point", horizon_steps=40, autoreset_mode=mode
    )
    singles = [gym.make(env_id, horizon_steps=40) for _ in STARTS]
    return vec, singles


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_info_holds_the_outcome_as_gymnasiums_vector_api(env_id):
    from gymnasium.vector import AutoresetMode

    options = {key: np.array([s[key] for s in STARTS]) for key in STARTS[0]}
    options["density_scale"] = np.ones(2)
    options["density_phase_rad"] = np.zeros(2)
    for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
        vec, singles = vector_and_singles(env_id, mode)
        _, info = vec.reset(seed=0, options=options)
        for key in OUTCOME:
            assert info[f"_{key}"].all()
        np.testing.assert_array_equal(info["reentered"], [False, False])
        assert info["reentered"].dtype == np.bool_
        np.testing.assert_array_equal(info["days_in_orbit"], [0.0, 0.0])
        np.testing.assert_array_equal(info["dv_used_m_s"], [0.0, 0.0])
        for i, single in enumerate(singles):
            single.reset(seed=0, options={key: float(value[i]) for key, value in options.items()})
        vec.action_space.seed(3)
        ended = [False, False]
        for _ in range(41):
            actions = vec.action_space.sample()
            _, _, terminated, truncated, info = vec.step(actions)
            for key in OUTCOME:
                assert info[f"_{key}"].all()  # every row has an outcome: the episode's, or the new one's
            for i, single in enumerate(singles):
                if ended[i]:
                    continue
                *_, single_info = single.step(actions[i])
                done = bool(terminated[i] or truncated[i])
                seen = info["final_info"] if done and mode is AutoresetMode.SAME_STEP else info
                assert seen[f"_{OUTCOME[0]}"][i]
                assert bool(seen["reentered"][i]) == single_info["reentered"]
                assert seen["days_in_orbit"][i] == pytest.approx(single_info["days_in_orbit"], rel=1e-9)
                assert seen["dv_used_m_s"][i] == pytest.approx(single_info["dv_used_m_s"], abs=1e-9)
                if done:
                    ended[i] = True
                    if mode is AutoresetMode.SAME_STEP:  # the row already holds the new episode
                        assert not info["reentered"][i] and info["days_in_orbit"][i] == 0.0
                        assert info["dv_used_m_s"][i] == 0.0
            if mode is AutoresetMode.NEXT_STEP:
                restarted = ~info["_burn_m_s"]  # NEXT_STEP: the rows that started anew in this step
                assert not info["reentered"][restarted].any()
                assert (info["days_in_orbit"][restarted] == 0.0).all()
                assert (info["dv_used_m_s"][restarted] == 0.0).all()
        assert all(ended)
        # A masked reset reports only the masked rows, as SyncVectorEnv.
        _, info = vec.reset(options={"reset_mask": np.array([False, True])})
        np.testing.assert_array_equal(info["_days_in_orbit"], [False, True])
        assert info["days_in_orbit"][1] == 0.0


def test_sb3_infos_hold_each_finished_episodes_outcome():
    pytest.importorskip("stable_baselines3")
    from orbit_env.envs.sb3 import SB3VecEnv

    # SB3VecEnv directly: the outcome is the adapter's, whatever make_sb3_vec_env wraps around it.
    vec = gym.make_vec(
        "OrbitRaising-v0",
        num_envs=2,
        vectorization_mode="vector_entry_point",
        horizon_steps=40,
        autoreset_mode="SameStep",
    )
    venv = SB3VecEnv(vec)
    venv.set_options(STARTS)
    venv.reset()
    finished = {}
    for _ in range(40):
        _, _, dones, infos = venv.step(np.zeros(2, dtype=np.int64))
        for i in np.flatnonzero(dones):
            finished.setdefault(int(i), infos[i])
        assert all(set(OUTCOME).isdisjoint(infos[i]) for i in np.flatnonzero(~dones))
    assert finished[0]["reentered"] is True and 0.0 < finished[0]["days_in_orbit"] < 40.0
    assert finished[1]["reentered"] is False and finished[1]["dv_used_m_s"] == 0.0


@pytest.mark.parametrize("env_id", [*ENV_IDS, *SOLAR_ENV_IDS])
def test_a_step_after_the_end_warns_as_cartpoles_does(env_id):
    import warnings

    env = gym.make(env_id, horizon_steps=2)
    env.reset(seed=0)
    for _ in range(2):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            *_, terminated, _, _ = env.step(env.action_space.sample() * 0)
        assert not [w for w in caught if "after the episode ended" in str(w.message)]
    assert terminated
    with pytest.warns(UserWarning, match=r"step\(\) called after the episode ended .* call reset\(\)"):
        env.step(env.action_space.sample() * 0)
    env.reset(seed=1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env.step(env.action_space.sample() * 0)
    assert not [w for w in caught if "after the episode ended" in str(w.message)]


def test_sb3_infos_hold_the_solar_missions_end():
    # The solar task's end: its date, the disposal burn and the verdict reach SB3's infos too.
    pytest.importorskip("stable_baselines3")
    from orbit_env.envs.sb3 import make_sb3_vec_env

    venv = make_sb3_vec_env(SOLAR_ENV_ID, num_envs=2, seed=0, horizon_steps=3)
    venv.reset()
    for _ in range(3):
        _, _, dones, infos = venv.step(np.zeros(2, dtype=np.int64))
    assert dones.all()
    for info in infos:
        assert {"complies", "disposal_dv_m_s", "date", "reentered", "episode"} <= set(info), info
        assert info["complies"] is True and info["disposal_dv_m_s"] >= 0.0 and info["episode"]["l"] == 3


@pytest.mark.parametrize("env_id", [*ENV_IDS, *SOLAR_ENV_IDS])
def test_sb3s_own_make_vec_env_makes_every_id(env_id):
    # Stable-Baselines3's make_vec_env asks gymnasium.make for render_mode="rgb_array" (retrying without it
    # only on a TypeError): every id must draw frames, the solar task's too (it refused them before).
    pytest.importorskip("stable_baselines3")
    pytest.importorskip("matplotlib")
    from stable_baselines3.common.env_util import make_vec_env

    venv = make_vec_env(env_id, n_envs=2, seed=0)
    assert venv.reset().shape == (2, *venv.observation_space.shape)
    venv.step(np.zeros((2, *venv.action_space.shape), dtype=venv.action_space.dtype))
    frame = venv.envs[0].render()
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8 and frame.std() > 0.0
    again = pickle.loads(pickle.dumps(venv.envs[0].unwrapped))  # the figure stays behind, drawn anew
    assert again.render().shape == (480, 640, 3)
    venv.close()


# --------------------------------------------------------------------------------------
# "orbit_env:OrbitRaising-v0" works without importing orbit_env first (docs/getting-started.md)
# --------------------------------------------------------------------------------------

MODULE_ID = """
import sys
import gymnasium as gym
assert "orbit_env" not in sys.modules
env = gym.make("orbit_env:OrbitRaising-v0")
env.reset(seed=0)
vec = gym.make_vec("orbit_env:OrbitRaisingContinuous-v0", num_envs=2, vectorization_mode="vector_entry_point")
print(type(env.unwrapped).__name__, type(vec.unwrapped).__name__, env.spec.id)
"""


def test_the_module_id_form_registers_the_envs_itself():
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", MODULE_ID], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["OrbitRaisingEnv", "OrbitRaisingVectorEnv", "OrbitRaising-v0"]
    # The page that says so.
    from pathlib import Path

    page = Path(__file__).parents[2] / "docs" / "getting-started.md"
    assert 'gym.make("orbit_env:OrbitRaising-v0")' in page.read_text()


# --------------------------------------------------------------------------------------
# Version history: the dynamics change under -v0 is recorded where users look
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_version_history_records_the_burn_relocation_fix(env_id):
    from pathlib import Path

    single = gym.make(env_id).unwrapped
    vec = gym.make_vec(env_id, num_envs=1, vectorization_mode="vector_entry_point").unwrapped
    for doc in (" ".join(type(single).__doc__.split()), " ".join(type(vec).__doc__.split())):
        history = doc[doc.index("Version History") :]
        assert "2026-12-03" in history and "burn relocation fix" in history
    assert "any change to the returns bumps the id's version" in " ".join(type(single).__doc__.split())
    changelog = " ".join((Path(__file__).parents[2] / "CHANGELOG.md").read_text().split())
    unreleased = changelog[changelog.index("## [Unreleased]") :]
    fixed = unreleased[unreleased.index("### Fixed") :]
    assert "2026-12-03 (the burn relocation fix)" in fixed and "bumps the id's" in fixed


# --------------------------------------------------------------------------------------
# Pickling carries the state, not the curves' table (which the process caches)
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_reset_env_pickles_small_and_continues_identically(env_id):
    import copy
    import pickle

    from orbit_env.decay.curves import universal_curves

    env = gym.make(env_id)
    env.reset(seed=4)
    actions = [env.action_space.sample() for _ in range(30)]
    for action in actions[:10]:
        env.step(action)
    data = pickle.dumps(env.unwrapped)
    assert len(data) < 20_000, len(data)  # was 19.7 MB: the curves' table through the task's cache
    twin = pickle.loads(data)
    assert twin.task.curves is universal_curves()  # rebuilt from the process's one table
    deep = copy.deepcopy(env.unwrapped)
    for action in actions[10:]:
        a, b, c = env.unwrapped.step(action), twin.step(action), deep.step(action)
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[0], c[0])
        assert a[1:] == b[1:] == c[1:]
    vec = gym.make_vec(env_id, num_envs=64, vectorization_mode="vector_entry_point")
    vec.reset(seed=4)
    vec.step(vec.action_space.sample())
    assert len(pickle.dumps(vec.unwrapped)) < 200_000  # 64 satellites' rows, no table


# --------------------------------------------------------------------------------------
# A start can be replayed: env.unwrapped.start_options gives it back bit for bit
# --------------------------------------------------------------------------------------


def _fixed_actions(env: gym.Env, kind: str, n: int) -> list:
    """``n`` actions: all coasts, or a random sequence fixed by its own seed."""
    space = env.action_space
    if kind == "coast":
        return [np.full(space.shape, -1.0, dtype=np.float32) if space.shape else 0 for _ in range(n)]
    space = copy.deepcopy(space)
    space.seed(7)
    return [space.sample() for _ in range(n)]


def _episode(env: gym.Env, actions: list, **reset: Any) -> tuple[np.ndarray, float, int]:
    """Reset, then step ``actions`` to the episode's end: the start's fields, the return, the steps."""
    from orbit_env.envs.state import STATE_FIELDS

    env.reset(**reset)
    start = np.array([getattr(env.unwrapped.task_state, name) for name in STATE_FIELDS])
    total = 0.0
    for k, action in enumerate(actions):
        _, reward, terminated, truncated, _ = env.step(action)
        total += reward
        if terminated or truncated:
            return start, total, k + 1
    raise AssertionError("the episode outlived its actions")


@pytest.mark.parametrize("kind", ["coast", "random"])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_a_drawn_start_replays_bit_for_bit_from_its_start_options(env_id, kind):
    # The reported heights do not give a start back (table A locates table B's heights a little
    # elsewhere: up to 30 m of perigee, 0.5 km of apogee, 0.3 day of return); the start options do.
    env = gym.make(env_id)
    actions = _fixed_actions(env, kind, DEFAULT_HORIZON_STEPS)
    for seed in range(100):
        start, total, steps = _episode(env, actions, seed=seed)
        options = env.unwrapped.start_options
        assert set(options) == {"curve_label", "curve_tau", "density_scale", "density_phase_rad"} | {
            "drag_coefficient",
            "area_m2",
            "dry_mass_kg",
            "propellant_mass_kg",
            "isp_s",
        }
        # Replayed from another state of the generator: nothing of the start is drawn.
        again, total_again, steps_again = _episode(env, actions, options=options)
        np.testing.assert_array_equal(again, start, err_msg=f"seed {seed}")
        assert abs(total_again - total) <= 1e-9 and steps_again == steps, (seed, total, total_again)
        assert env.unwrapped.start_options == options


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_vector_starts_replay_bit_for_bit_automatic_resets_included(env_id):
    from orbit_env.envs.state import STATE_FIELDS

    n = 100
    env = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", horizon_steps=40)
    single = gym.make(env_id, horizon_steps=40)
    rng = np.random.default_rng(3)

    def actions() -> np.ndarray:
        if env.single_action_space.shape:
            return rng.uniform(-1.0, 1.0, (n, 1)).astype(np.float32)
        return rng.integers(0, 4, n)

    env.reset(seed=0)
    starts = env.unwrapped.task_state.data.copy()
    done = np.zeros(n, dtype=bool)
    for _ in range(60):  # every satellite ends once (truncation at 40), most restart automatically
        _, _, terminated, truncated, _ = env.step(actions())
        starts[:, done] = env.unwrapped.task_state.data[:, done]  # restarted in this step (NEXT_STEP)
        done = terminated | truncated
    options = env.unwrapped.start_options
    assert all(value.shape == (n,) for value in options.values())
    fixed = [actions() for _ in range(40)]

    def play() -> tuple[np.ndarray, np.ndarray]:
        env.reset(options=options)
        first = env.unwrapped.task_state.data.copy()
        total, over = np.zeros(n), np.zeros(n, dtype=bool)
        for action in fixed:
            _, reward, terminated, truncated, _ = env.step(action)
            total += np.where(over, 0.0, reward)
            over |= terminated | truncated
        return first, total

    first, total = play()
    np.testing.assert_array_equal(first[: len(STATE_FIELDS)], starts[: len(STATE_FIELDS)])
    again, total_again = play()
    np.testing.assert_array_equal(again, first)
    np.testing.assert_allclose(total_again, total, rtol=0.0, atol=1e-9)
    # Row i's options start sub-environment i's mission in a single environment.
    for i in range(0, n, 10):
        single.reset(options={name: value[i] for name, value in options.items()})
        state = single.unwrapped.task_state
        for row, name in enumerate(STATE_FIELDS[:8]):
            assert getattr(state, name) == pytest.approx(first[row, i], rel=1e-12, abs=1e-9), name


@pytest.mark.parametrize(
    ("options", "named"),
    [
        ({"curve_label": 1.0, "curve_tau": 5.0}, r"curve_label(\[0\])?=1 is out of range; allowed: -20.7\d* to -1.3"),
        ({"curve_label": -5.0, "curve_tau": -0.5}, r"curve_tau(\[0\])?=-0.5 is out of range; allowed: at least 0"),
        ({"curve_label": -5.0, "curve_tau": float("nan")}, r"reset option curve_tau=.*nan.* must be finite"),
        ({"curve_label": -5.0}, r"reset option curve_label needs \['curve_label', 'curve_tau'\] together"),
        ({"curve_tau": 5.0}, r"reset option curve_tau needs \['curve_label', 'curve_tau'\] together"),
        ({"curve_label": -5.0, "curve_tau": 5.0, "perigee_km": 300.0}, r"\['perigee_km'\] and .* both pin the orbit"),
        # Past the domain's top: the point's heights are out of it.
        ({"curve_label": -5.0, "curve_tau": 26.0}, r"curve_tau(\[0\])?=26\.0.*outside the universal curves' domain"),
        ({"curve_label": -5.0, "curve_tau": 5.0, "density_scale": 0.0}, r"density_scale(\[0\])?=0 is out of range"),
    ],
)
def test_bad_curve_options_are_refused_naming_the_key(options, named):
    env = gym.make("OrbitRaising-v0")
    with pytest.raises(ValueError, match=named):
        env.reset(seed=0, options=options)
    vec = gym.make_vec("OrbitRaising-v0", num_envs=3, vectorization_mode="vector_entry_point")
    with pytest.raises(ValueError, match=named):
        vec.reset(seed=0, options={key: np.full(3, value) for key, value in options.items()})


# --------------------------------------------------------------------------------------
# `import orbit_env` registers the ids whichever is imported first, without importing Gymnasium itself
# --------------------------------------------------------------------------------------

IMPORT_ORDERS = {
    "orbit_env first": "import orbit_env\nimport gymnasium",
    "gymnasium first": "import gymnasium\nimport orbit_env",
    "a gymnasium submodule after": "import orbit_env\nimport gymnasium.spaces\nimport gymnasium",
}


@pytest.mark.parametrize("order", IMPORT_ORDERS.values(), ids=IMPORT_ORDERS.keys())
def test_the_ids_are_registered_in_either_order_of_the_imports(order: str) -> None:
    import subprocess
    import sys

    script = order + "\nenv = gymnasium.make('OrbitRaising-v0')\nenv.reset(seed=0)\nprint(env.spec.id)"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["OrbitRaising-v0"]


def test_a_decay_command_imports_neither_gymnasium_nor_the_progress_bars_nor_the_pools() -> None:
    """What a lifetime command never uses is not imported (Gymnasium alone is 30 ms of its 0.25 s)."""
    import subprocess
    import sys

    script = (
        "import sys\nfrom orbit_env.cli import main\n"
        "main(['lifetime', '--perigee', '300', '--apogee', '350', '--json'])\n"
        "print('imported:', *[m for m in ('gymnasium', 'tqdm', 'concurrent.futures', 'orbit_env.agents.evaluate') "
        "if m in sys.modules])"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert '"days"' in done.stdout  # the command ran
    assert done.stdout.strip().splitlines()[-1] == "imported:"
