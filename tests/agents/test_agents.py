"""Hand-coded policies, the evaluation harness, training smoke test and the CLI commands."""

import json

import gymnasium
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
import orbit_env.agents.evaluate as evaluate_module
from orbit_env.agents.evaluate import (
    EVAL_SEED,
    Episodes,
    all_policies,
    hand_coded_policies,
    paired_difference,
    run_episodes,
    summarize,
)
from orbit_env.agents.policies import HAND_CODED, AllAtOnce, ApogeeThreshold, Greedy, NeverBurn
from orbit_env.cli import main
from orbit_env.envs import task as task_model
from orbit_env.envs.config import OrbitRaisingConfig


@pytest.fixture(scope="module")
def baseline_results():
    policies = hand_coded_policies("OrbitRaising-v0")
    return {name: run_episodes("OrbitRaising-v0", p, episodes=60, seed=EVAL_SEED) for name, p in policies.items()}


def test_never_burns_nothing_and_all_at_once_empties_the_tank(baseline_results):
    never, all_at_once = baseline_results["never"], baseline_results["all_at_once"]
    assert np.all(never.dv_m_s == 0.0)
    np.testing.assert_allclose(never.returns, never.lifetime_days)  # no cost without burns
    capacity = OrbitRaisingConfig().delta_v_capacity_m_s
    # The tank empties unless the 4000 km apogee cap or an early re-entry stops it.
    assert np.median(all_at_once.dv_m_s) == pytest.approx(capacity, rel=1e-6)
    assert np.all(all_at_once.lifetime_days >= never.lifetime_days - 1e-6)


def test_greedy_beats_never_and_all_at_once(baseline_results):
    # The look-ahead buys days where they pay; on 60 episodes it must beat both by 5%.
    greedy = baseline_results["greedy"].returns.mean()
    assert greedy > 1.05 * baseline_results["never"].returns.mean()
    assert greedy > 1.05 * baseline_results["all_at_once"].returns.mean()


def test_summary_capture_is_relative_to_never_and_dp(baseline_results):
    fake = dict(baseline_results)
    fake["dp"] = baseline_results["greedy"]
    table = summarize(fake)
    assert table["never"]["capture"] == pytest.approx(0.0)
    assert table["dp"]["capture"] == pytest.approx(1.0)
    assert set(table["never"]) == {"mean_return", "std_return", "mean_lifetime_days", "mean_dv_m_s", "capture"}


def test_paired_difference_is_against_the_best_hand_coded_policy(baseline_results):
    greedy = baseline_results["greedy"]
    wobble = np.where(np.arange(greedy.returns.size) % 2 == 0, 1.0, -0.5)
    fake = dict(baseline_results, ppo=Episodes(greedy.returns + wobble, greedy.lifetime_days, greedy.dv_m_s))
    paired = paired_difference(fake)
    assert paired["baseline"] == "greedy" and paired["policy"] == "ppo"
    assert paired["mean"] == pytest.approx(wobble.mean())
    assert paired["stderr"] == pytest.approx(wobble.std(ddof=1) / np.sqrt(wobble.size))
    assert (paired["better"], paired["worse"]) == ((wobble > 0).sum(), (wobble < 0).sum())
    assert paired_difference(baseline_results) is None  # no ppo
    to_dp = paired_difference(dict(fake, dp=greedy), baseline="dp")
    assert to_dp["baseline"] == "dp" and to_dp["mean"] == pytest.approx(wobble.mean())
    assert paired_difference(fake, baseline="dp") is None  # no dp


@pytest.mark.parametrize("cls", [NeverBurn, AllAtOnce, ApogeeThreshold, Greedy])
def test_policies_answer_sb3_predict_single_and_batched(cls):
    env = gymnasium.make("OrbitRaising-v0")
    obs, _ = env.reset(seed=3)
    policy = cls()
    action, state = policy.predict(obs)
    assert state is None and env.action_space.contains(int(action))
    batch, _ = policy.predict(np.stack([obs, obs]))
    assert batch.shape == (2,)
    continuous = cls(continuous=True)
    box = gymnasium.make("OrbitRaisingContinuous-v0").action_space
    assert box.contains(continuous.predict(obs)[0])
    with pytest.raises(ValueError, match="shape"):
        policy.predict(np.zeros(5))


class _Twice(NeverBurn):
    """A policy that is only declared in `HAND_CODED` (by the test)."""

    name = "twice"


def test_every_hand_coded_policy_is_evaluated_in_its_declared_order(monkeypatch):
    # A new hand-coded policy is declared once, in HAND_CODED; `evaluate` scores and lists it.
    monkeypatch.setitem(HAND_CODED, _Twice.name, _Twice)
    monkeypatch.setattr(evaluate_module, "load_model", lambda *args: None)  # no learned agent
    policies = all_policies("OrbitRaising-v0", include_dp=False)
    assert list(policies) == list(HAND_CODED)
    assert isinstance(policies["twice"], _Twice)


def test_apogee_threshold_burns_only_below_threshold():
    policy = ApogeeThreshold(threshold_km=700, target_km=1000)
    obs = np.array([[0.36, 0.65, 0.3, 0, 0.5, 0, 0], [0.36, 0.9, 0.3, 0, 0.5, 0, 0]], dtype=np.float32)
    burns = policy.burns_m_s(task_model.decode(policy.task, obs))
    # 360 x 650 -> 360 x 1000 km needs about 90 m/s: the 100 m/s size; above 700 km nothing.
    assert burns[0] == 100.0 and burns[1] == 0.0


class Returns:
    """A policy whose predict returns what ``make`` makes of the observations (a bad policy's stand-in)."""

    def __init__(self, make):
        self.make = make

    def predict(self, observations, deterministic=True):
        return self.make(observations), None


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda o: np.full(len(o), 2.7), r"Returns.predict returned float64 actions .* \(2.7 first\); allowed: int"),
        (lambda o: np.full(len(o), 2.0), r"returned float64 actions .*\(2.0 first\).*refuses a float action"),
        (lambda o: np.full(len(o), -1), r"returned action -1; allowed: integers in \[0, 3\]"),
        (lambda o: np.full(len(o), np.nan), r"returned an action that is not finite: nan"),
        (lambda o: np.zeros((len(o), 1)), r"returned actions of shape \(5, 1\), not \(5,\) \(5 observations\)"),
        (lambda o: ["a"] * len(o), r"returned actions that are not numbers"),
    ],
    ids=["fraction", "whole float", "negative", "nan", "shape", "text"],
)
def test_a_policys_bad_actions_are_refused_naming_it_not_rounded_or_wrapped(make, message):
    # evaluate wrote them into an int64 array: 2.7 flew the 30 m/s burn, and in the solar task -1 the largest.
    from orbit_env.agents.solar import fly_model

    with pytest.raises(ValueError, match=message):
        run_episodes("OrbitRaising-v0", Returns(make), episodes=5, seed=0)
    with pytest.raises(ValueError, match=message.replace("(5", "(3").replace("5 obs", "3 obs")):
        fly_model(Returns(make), 3, 0)
    assert run_episodes("OrbitRaising-v0", Returns(lambda o: np.full(len(o), 2)), episodes=5, seed=0).returns.size


def test_the_solar_task_is_sent_to_its_own_evaluation_and_every_id_is_named():
    with pytest.raises(ValueError, match=r"OrbitRaisingSolar-v0 is scored by orbit_env.agents.solar.evaluate_solar"):
        run_episodes("OrbitRaisingSolar-v0", NeverBurn(), episodes=2)
    with pytest.raises(ValueError, match=r"allowed: OrbitRaising-v0, .*, OrbitRaisingSolarContinuous-v0$"):
        run_episodes("Foo-v0", NeverBurn(), episodes=2)


@pytest.mark.parametrize("env_id", sorted(evaluate_module.SHIPPED_MODELS))
def test_the_shipped_models_load_to_act_without_unpickling_their_schedules(env_id):
    # The schedules are closures that another cloudpickle cannot rebuild: SB3 warned "Could not deserialize
    # object learning_rate" on every evaluation. Acting needs none of them, so load_model replaces them.
    import warnings

    from orbit_env.agents.evaluate import load_model

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        name, model = load_model(env_id)
    messages = [str(w.message) for w in caught]
    assert name == "ppo" and not [m for m in messages if "deserialize" in m], messages
    obs, _ = gymnasium.make(env_id).reset(seed=0)
    assert gymnasium.make(env_id).action_space.contains(model.predict(obs, deterministic=True)[0])


def test_the_shipped_ppo_beats_the_greedy_look_ahead_on_validation_episodes():
    # Issue 4: PPO must beat every hand-coded policy; greedy is the best of them. Measured on
    # 1000 validation episodes (seed 777, neither training's 0 nor evaluation's 12345):
    # +0.73 +- 0.08 days per episode. On these 300 the standard error is about 0.15 day,
    # so a lead above 0 leaves a margin of some 5 standard errors; a changed env (physics,
    # observation) that the model no longer fits fails it.
    from orbit_env.agents.evaluate import load_model

    greedy = run_episodes("OrbitRaising-v0", Greedy(), episodes=300, seed=777).returns
    ppo = run_episodes("OrbitRaising-v0", load_model("OrbitRaising-v0")[1], episodes=300, seed=777).returns
    assert (ppo - greedy).mean() > 0.0
    assert np.sum(ppo < greedy - 1.0) <= 0.02 * ppo.size  # 5 of 1000 worse by a day or more


def test_train_smoke(tmp_path):
    from orbit_env.agents.train import train

    result = train(out_dir=tmp_path, total_timesteps=2048, progress=False)
    assert result.model_path.is_file()
    from stable_baselines3 import PPO

    model = PPO.load(result.model_path, device="cpu")
    episodes = run_episodes("OrbitRaising-v0", model, episodes=4, seed=1)
    assert np.all(np.isfinite(episodes.returns))


def test_evaluate_cli_json_without_dp(capsys):
    status = main(["evaluate", "--episodes", "8", "--no-dp", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0
    assert out["env"] == "OrbitRaising-v0" and out["episodes"] == 8
    assert {"never", "all_at_once", "apogee_threshold", "greedy", "ppo"} <= set(out["policies"])
    assert out["paired_difference"]["policy"] == "ppo"
    # A submission says what made the rows its reader cannot see: no DP here, the shipped model.
    assert out["dp_policy"] is None and out["model"] == "shipped"


@pytest.mark.parametrize(
    "argv",
    [["evaluate", "--env", "CartPole-v1"], ["evaluate", "--episodes", "0"], ["train", "--config", "/nonexistent.toml"]],
)
def test_bad_agent_commands_fail_in_one_line(capsys, argv):
    try:
        status = main(argv)
    except SystemExit as raised:
        status = raised.code
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1


def test_the_decision_is_not_trivial_on_the_default_task(baseline_results):
    # Issue 4: on OrbitRaising-v0's defaults the optimum must beat both never burning and
    # burning everything at once by at least 10% of return (measured on the 1000 evaluation
    # episodes: +21.2% and +23.1%). The DP policy, evaluated in the env, on the fixture's 60 episodes.
    from orbit_env.agents.evaluate import dp_policy

    dp = run_episodes("OrbitRaising-v0", dp_policy("OrbitRaising-v0"), episodes=60, seed=EVAL_SEED).returns.mean()
    assert dp >= 1.10 * baseline_results["never"].returns.mean()
    assert dp >= 1.10 * baseline_results["all_at_once"].returns.mean()


def shipped(name):
    from importlib import resources

    return str(resources.files("orbit_env.agents").joinpath("models", name))


def test_evaluate_checks_the_model_before_any_heavy_work(tmp_path, monkeypatch, capsys):
    from orbit_env.agents import evaluate as evaluate_module

    def heavy(*args, **kwargs):
        raise AssertionError("the DP or a policy ran before the model was checked")

    monkeypatch.setattr(evaluate_module, "dp_policy", heavy)
    monkeypatch.setattr(evaluate_module, "hand_coded_policies", heavy)
    (tmp_path / "bad.zip").write_text("not a model")
    cases = [
        (["--model", str(tmp_path / "none.zip")], "no model at"),
        (["--model", str(tmp_path / "bad.zip")], "is not a Stable-Baselines3 model"),
        (
            ["--env", "OrbitRaisingContinuous-v0", "--model", shipped("ppo_orbit_raising.zip")],
            "acts in the action space Discrete(4), but OrbitRaisingContinuous-v0 has Box(1,)",
        ),
        (
            ["--model", shipped("ppo_orbit_raising_continuous.zip")],
            "acts in the action space Box(1,), but OrbitRaising-v0 has Discrete(4)",
        ),
    ]
    for argv, message in cases:
        assert main(["evaluate", *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err


def test_evaluate_warns_of_a_model_trained_on_another_env(capsys):
    status = main(
        ["evaluate", "--no-dp", "--episodes", "4", "--json", "--model", shipped("ppo_orbit_raising_uncertain.zip")]
    )
    captured = capsys.readouterr()
    assert status == 0
    assert "was trained on OrbitRaisingUncertain-v0, not OrbitRaising-v0" in captured.err
    assert "ppo" in json.loads(captured.out)["policies"]


def test_evaluate_scores_a_model_of_another_algorithm(tmp_path, capsys):
    from stable_baselines3 import A2C

    from orbit_env.agents.evaluate import model_algorithm
    from orbit_env.envs.sb3 import make_sb3_vec_env

    model = A2C("MlpPolicy", make_sb3_vec_env("OrbitRaising-v0", num_envs=2, seed=0), device="cpu", seed=0)
    model.orbit_env = {"env_id": "OrbitRaising-v0", "env": {}}
    model.save(tmp_path / "a2c.zip")
    assert model_algorithm(tmp_path / "a2c.zip") == "a2c"
    assert model_algorithm(shipped("ppo_orbit_raising.zip")) == "ppo"
    assert main(["evaluate", "--no-dp", "--episodes", "4", "--json", "--model", str(tmp_path / "a2c.zip")]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert "a2c" in out["policies"] and out["paired_difference"]["policy"] == "a2c"
    assert "warning" not in captured.err


def test_the_shipped_continuous_ppo_captures_most_of_the_optimums_gain():
    # Measured on the 1000 evaluation episodes (seed 12345): 99.2% of the gain of the DP over
    # burns spaced by 10 m/s (docs/agents.md). Here 200 validation episodes (seed 777) against
    # never burning and the greedy look-ahead, cheap stand-ins for the DP's 60 s solve: a
    # changed env that the model no longer fits falls below them.
    from orbit_env.agents.evaluate import load_model

    env_id = "OrbitRaisingContinuous-v0"
    base = hand_coded_policies(env_id)
    never = run_episodes(env_id, base["never"], episodes=200, seed=777).returns.mean()
    greedy = run_episodes(env_id, base["greedy"], episodes=200, seed=777).returns.mean()
    ppo = run_episodes(env_id, load_model(env_id)[1], episodes=200, seed=777).returns.mean()
    assert ppo > greedy - 1.0 and ppo - never > 0.9 * (greedy - never)


def test_evaluate_without_the_dp_prints_no_capture_footer(capsys):
    assert main(["evaluate", "--episodes", "4", "--no-dp"]) == 0
    out = capsys.readouterr().out
    assert "ppo - greedy, paired" in out and "capture =" not in out
