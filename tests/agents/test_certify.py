"""The search for plans that beat a policy (``orbit-env evaluate --certify``), on cheap policies."""

import json

import gymnasium as gym
import numpy as np
import pytest

from orbit_env.agents.certify import certify
from orbit_env.agents.evaluate import dp_policy, run_episodes
from orbit_env.agents.policies import Greedy, NeverBurn


def test_the_search_beats_a_policy_that_never_burns_and_replays_its_winners():
    certificate = certify("OrbitRaising-v0", episodes=12, seed=3, rounds=1, perturbations=4, policy=NeverBurn())
    summary = certificate.summary()
    # The reference is the policy's own return in the env, start by start (the evaluation's start
    # orbits, pinned by their heights: lifetimes within 5e-4 of the unpinned ones).
    np.testing.assert_allclose(
        certificate.dp_returns, run_episodes("OrbitRaising-v0", NeverBurn(), 12, 3).returns, rtol=5e-4
    )
    for i in range(3):
        env = gym.make("OrbitRaising-v0")
        env.reset(options={"perigee_km": certificate.perigee_km[i], "apogee_km": certificate.apogee_km[i]})
        total, done = 0.0, False
        while not done:
            _, reward, terminated, truncated, _ = env.step(0)
            total, done = total + reward, terminated or truncated
        assert total == pytest.approx(certificate.dp_returns[i], rel=1e-9)
    # Never burning loses the days after re-entry: the early plans find burns that pay.
    assert summary["beaten_above_0.1_day"] >= 3 and summary["worst_gap_days"] > 10.0
    assert np.all(certificate.best_returns >= certificate.dp_returns - 1e-9)
    # Every winner's return is the one gymnasium.make gives when the plan is replayed.
    assert summary["replay_max_error_days"] < 1e-6
    # The policy, the DP policy and its burns as a plan (the search's first plan where it earns more),
    # 4^3 early plans, the perturbations.
    assert summary["plans_scored"] == 12 * (1 + 2 + 64 + 4)
    # It names the policy it certified, not the DP's (it said "DP policy's mean return" of any policy).
    from orbit_env.agents.certify import format_certificate

    text = format_certificate(summary)
    assert summary["policy"] == "policy NeverBurn" and "policy NeverBurn's mean return" in text
    assert "DP" not in text and "solar" not in text


def test_the_search_rarely_beats_a_good_policy_by_much():
    # Greedy is within about a day of the optimum (docs/agents.md): the gaps found stay small.
    certificate = certify("OrbitRaising-v0", episodes=12, seed=3, rounds=2, perturbations=4, policy=Greedy())
    assert certificate.summary()["mean_gap_days"] < 2.0


def test_certify_refuses_an_unknown_density_and_the_cli_prints_json(capsys):
    with pytest.raises(ValueError, match="known, constant density"):
        certify("OrbitRaisingUncertain-v0", episodes=2)
    from orbit_env.cli import main

    assert main(["evaluate", "--certify", "--env", "OrbitRaisingUncertain-v0"]) == 2
    assert "known, constant density" in capsys.readouterr().err
    # The rollout plays the DP's task model: not with a hidden density (its optimum is the oracle's).
    with pytest.raises(ValueError, match="rollout needs a known, constant density"):
        dp_policy("OrbitRaisingUncertain-v0", rollout=True)


def test_certify_summary_is_json():
    certificate = certify("OrbitRaising-v0", episodes=3, seed=1, rounds=0, perturbations=1, policy=NeverBurn())
    out = json.loads(json.dumps(certificate.summary()))
    assert out["episodes"] == 3 and out["env"] == "OrbitRaising-v0"


def test_the_solar_certificate_flies_each_missions_own_dp_and_replays_its_plan():
    from orbit_env.agents.solar import fly, starts
    from orbit_env.agents.solar_dp import SolarDP

    certificate = certify("OrbitRaisingSolar-v0", episodes=2, seed=5, rounds=1, perturbations=3, workers=1)
    summary = certificate.summary()
    # The reference is each mission's DP flown on the task model, as evaluate's dp row flies it.
    task = gym.make("OrbitRaisingSolar-v0", solar_split="test").unwrapped.task  # certify's default, as evaluate's
    options = starts(task, 2, 5)
    for i in range(2):
        one = {key: value[i : i + 1] for key, value in options.items()}
        dp = SolarDP(task, float(one["start_day"][0]))
        assert fly(task, one, dp.burns_m_s).returns[0] == pytest.approx(certificate.dp_returns[i], abs=1e-9)
    # The DP's burns replayed open-loop in the vector env give its return back.
    assert summary["replay_max_error_days"] < 1e-9
    assert np.all(certificate.best_returns >= certificate.dp_returns - 1e-9)
    assert summary["plans_scored"] == 2 * (1 + 64 + 3)  # the DP's plan, 4^3 early plans, the perturbations
    # The test split's missions start on or after 2009-01-01.
    assert summary["worst_start_date"] >= "2009-01-01" and len(summary["worst_start_date"]) == 10


def test_certify_refuses_the_options_it_would_ignore(capsys):
    from orbit_env.cli import main

    assert main(["evaluate", "--certify", "--plot", "x.png", "--model", "m.zip"]) == 2
    assert "--certify searches plans against the DP policy: it takes no --model or --plot" in capsys.readouterr().err
