"""What an engineer scoring hand-coded policies on the known-density envs found (2026-12-06, second review).

Each test failed before its fix: a policy's state silently dropped, a policy's own ``bind`` called (and an
oracle's stale binding read), the oracle's lookahead ignored, a certificate that started from the policy's
plan only, refusals that named the wrong thing, a capture column without captures.
"""

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the ids)
from orbit_env.agents.certify import certify
from orbit_env.agents.evaluate import (
    OracleDP,
    dp_policy,
    format_table,
    hand_coded_policies,
    predicted_actions,
    run_episodes,
    task_of,
)

ENV = "OrbitRaising-v0"
UNCERTAIN = "OrbitRaisingUncertain-v0"
OBS = np.zeros((3, 7), np.float32)


class Counter:
    """Burns 10 m/s every 30th step it is asked, counting in its state: memory the harness does not keep."""

    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        count = 0 if state is None else state
        return np.full(len(obs), 1 if count % 30 == 0 else 0), count + 1


def test_a_policy_that_returns_a_state_is_refused_not_scored_without_it():
    # It had burned at every step (its state None each time): 271 m/s a mission for a rule of ~130.
    with pytest.raises(ValueError, match=r"Counter\.predict returned a state \(int\).*memoryless"):
        run_episodes(ENV, Counter(), 4, 1)


def test_a_plain_function_is_scored_as_its_class():
    def half_year(obs):
        return np.where((obs[:, 4] < 1 / 3) & (obs[:, 2] >= 0.03), 2, 0)

    class HalfYear:
        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return half_year(np.atleast_2d(obs)), state

    by_function = run_episodes(ENV, half_year, 20, 3)
    by_class = run_episodes(ENV, HalfYear(), 20, 3)
    np.testing.assert_array_equal(by_function.returns, by_class.returns)
    assert by_function.dv_m_s.sum() > 0.0  # the rule burned: the comparison saw burns


def test_a_policys_own_bind_is_not_the_harness_hook():
    # run_episodes had called any policy's bind(env, rows): a user's bind(config) crashed with a TypeError.
    class WithBind:
        def bind(self, config):
            raise AssertionError("called by the harness")

        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return np.zeros(len(obs), dtype=np.int64), state

    never = run_episodes(ENV, hand_coded_policies(ENV)["never"], 10, 2)
    mine = run_episodes(ENV, WithBind(), 10, 2)
    np.testing.assert_array_equal(mine.returns, never.returns)


def test_the_oracle_is_unbound_after_its_episodes_and_refuses_to_be_read_inside_another_policy():
    # After a run the oracle kept reading that run's vector env: wrapped in another policy, it acted on the
    # old episodes' densities (203.75 days against its own 352.20 on one start), or crashed on a shape.
    oracle = OracleDP(task_of(UNCERTAIN).config, (0.5, 2.0), rungs=2, grid=(16, 1, 1))
    run_episodes(UNCERTAIN, oracle, 3, 4)
    assert oracle.env is None

    class Wrap:
        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return oracle.predict(obs, state, episode_start, deterministic)

    with pytest.raises(ValueError, match="score it directly"):
        run_episodes(UNCERTAIN, Wrap(), 3, 4)


def test_the_oracle_refuses_a_lookahead_it_would_ignore():
    # evaluate --dp-lookahead 2 on the uncertain env had reported lookahead 2 for the lookahead-1 oracle.
    with pytest.raises(ValueError, match="the lookahead 2 needs a known, constant density"):
        dp_policy(UNCERTAIN, lookahead=2)


def test_predict_without_deterministic_and_non_numeric_actions_are_named():
    class NoKeyword:
        def predict(self, obs):
            return np.zeros(len(obs), dtype=np.int64), None

    with pytest.raises(ValueError, match=r"NoKeyword\.predict must take predict\(observation, state=None"):
        predicted_actions(NoKeyword(), OBS, gym.spaces.Discrete(4))

    class Text:
        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return np.array(["0"] * len(obs)), state

    # '0' converted to 0.0 and was reported as "<U1 actions for a discrete space (0.0 first)".
    with pytest.raises(ValueError, match=r"Text\.predict returned actions that are not numbers \(<U1\)"):
        predicted_actions(Text(), OBS, gym.spaces.Discrete(4))


def test_an_action_beyond_float32_is_refused_not_clipped_to_a_full_burn():
    # 1e300 is finite in float64, inf in the Box's float32: it became the full burn with a RuntimeWarning.
    class Huge:
        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return np.full((len(obs), 1), 1e300), state

    space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    with pytest.raises(ValueError, match=r"Huge\.predict returned action 1e\+300, beyond float32"):
        predicted_actions(Huge(), OBS, space)


def test_a_policys_certificate_starts_from_the_dp_policys_plan_where_it_earns_more():
    # It searched from the policy's own plan only and reported gaps below what the DP policy already shows.
    never = hand_coded_policies(ENV)["never"]
    dp = certify(ENV, 12, 5, rounds=0)  # the DP policy's returns on the same pinned starts
    mine = certify(ENV, 12, 5, rounds=0, policy=never)
    assert np.all(mine.best_returns >= dp.dp_returns - 1e-9)
    assert np.any(dp.dp_returns > mine.dp_returns + 1.0)  # the DP beats never somewhere: the check has teeth
    with pytest.raises(ValueError, match="dp_rollout chooses the DP policy to certify"):
        certify(ENV, 2, policy=never, dp_rollout=True)


def test_certify_refuses_no_dp():
    done = subprocess.run(
        [sys.executable, "-m", "orbit_env.cli", "evaluate", "--certify", "--no-dp", "--episodes", "2"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    assert "--certify searches plans against the DP policy: it takes no --no-dp" in done.stderr


def test_the_table_has_a_capture_column_only_with_captures_and_aligns_a_wide_spread():
    row = {"mean_return": 757.4, "std_return": 1020.9, "mean_lifetime_days": 1810.5, "mean_dv_m_s": 79.2}
    table = {"never": {**row, "std_return": 473.6, "capture": None}, "greedy_constant": {**row, "capture": None}}
    lines = format_table(ENV, 2, 1, table).split("\n")
    assert "capture" not in lines[1]
    assert len({len(line) for line in lines[1:]}) == 1  # header and rows end in the same column
    assert lines[1].index("return") + len("return") == lines[2].index(" +- ") + len(" +-  473.6")
    captured = {name: {**values, "capture": 0.5} for name, values in table.items()}
    lines = format_table(ENV, 2, 1, captured).split("\n")
    assert lines[1].endswith("capture") and len({len(line) for line in lines[1:3]}) == 1


def test_every_episodes_return_is_written_for_the_paired_differences(tmp_path, capsys):
    # `--json` gave only means: a paired difference could not be recomputed, or tested otherwise, from the command.
    import csv
    import json

    from orbit_env.cli import main

    path = tmp_path / "returns.csv"
    assert main(["evaluate", "--episodes", "30", "--no-dp", "--json", "--returns", str(path)]) == 0
    result = json.loads(capsys.readouterr().out)
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [int(row["episode"]) for row in rows] == list(range(30))
    assert list(rows[0])[1:] == list(result["policies"])
    pair = result["paired_difference"]
    differences = np.array([float(row[pair["policy"]]) - float(row[pair["baseline"]]) for row in rows])
    assert differences.mean() == pytest.approx(pair["mean"], abs=1e-9)
    for name, summary in result["policies"].items():
        assert np.mean([float(row[name]) for row in rows]) == pytest.approx(summary["mean_return"], abs=1e-9)
    assert main(["evaluate", "--certify", "--returns", str(path)]) == 2  # the certificate scores no episodes
    assert "it takes no --returns" in capsys.readouterr().err


def test_the_learned_row_takes_the_name_given(capsys):
    # --model mine.zip was always the `ppo` row (by its algorithm): two PPO models could not be told apart.
    import json

    from orbit_env.cli import main

    assert main(["evaluate", "--episodes", "10", "--no-dp", "--json", "--name", "mine"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert list(result["policies"])[-1] == "mine" and "ppo" not in result["policies"]
    assert result["paired_difference"]["policy"] == "mine"
    assert main(["evaluate", "--episodes", "10", "--no-dp", "--name", "never"]) == 2
    assert "may not be named 'never'" in capsys.readouterr().err


def test_a_policy_that_acts_otherwise_on_the_same_observations_is_flagged():
    # A random policy scored 249.44 and 249.98 in two runs, without a word.
    rng = np.random.default_rng(0)

    def coin(obs):
        return rng.integers(0, 2, len(obs))

    with pytest.warns(UserWarning, match="coin acts otherwise on the same observations"):
        run_episodes(ENV, coin, 40, 1)


RULES = '''
import numpy as np

from orbit_env.agents.policies import HAND_CODED


class Greedy:
    """The package's greedy look-ahead, made with no arguments: it must score as the greedy row."""

    def __init__(self):
        from orbit_env.agents.evaluate import hand_coded_policies

        self.inner = hand_coded_policies("OrbitRaising-v0")["greedy"]

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return self.inner.predict(observation, deterministic=deterministic)


def idle(observations):
    return np.zeros(len(np.atleast_2d(observations)), dtype=np.int64)


class NeedsArguments:
    def __init__(self, threshold):
        self.threshold = threshold

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        return np.zeros(len(observation), dtype=np.int64), None


NOT_A_POLICY = 3
never = idle  # a row the evaluation has
'''


def test_a_policy_of_ones_own_is_scored_from_its_file_beside_the_others(capsys, tmp_path):
    import json

    from orbit_env.cli import main

    rules = tmp_path / "rules.py"
    rules.write_text(RULES)
    flags = ["evaluate", "--episodes", "20", "--no-dp", "--json"]
    assert main([*flags, "--policy", f"{rules}:Greedy", "--policy", f"{rules}:idle"]) == 0
    result = json.loads(capsys.readouterr().out)
    policies = result["policies"]
    assert list(policies)[-2:] == ["Greedy", "idle"]
    # The same episodes: the greedy rule scores as the package's own row, doing nothing as never burning.
    assert policies["Greedy"]["mean_return"] == policies["greedy"]["mean_return"]
    assert policies["idle"]["mean_return"] == policies["never"]["mean_return"]
    pairs = {(pair["policy"], pair["baseline"]): pair for pair in result["paired_policies"]}
    assert pairs[("Greedy", "greedy")]["mean"] == 0.0 and pairs[("idle", "greedy")]["mean"] < 0.0
    assert result["paired_difference"]["policy"] == "ppo"  # the learned agent's pair as before
    refused = [
        ([f"{rules}:NeedsArguments"], "the class NeedsArguments must be made with no arguments"),
        ([f"{rules}:NOT_A_POLICY"], "NOT_A_POLICY has no predict and is not a function"),
        ([f"{rules}:missing"], f"{rules} has no missing"),
        ([f"{tmp_path / 'nowhere.py'}:x"], "no file"),
        (["no_such_module_here:x"], "no module no_such_module_here"),
        (["rules.py"], "give FILE.py:NAME or MODULE:NAME"),
        ([f"{rules}:idle", f"{rules}:idle"], "idle is the name of another row"),
        ([f"{rules}:never"], "never is the name of another row"),
        ([f"{rules}:Greedy", "numpy:never"], "has no never"),
    ]
    for specs, message in refused:
        assert main([*flags, *(part for spec in specs for part in ("--policy", spec))]) == 2
        assert message in capsys.readouterr().err, specs
    assert main(["evaluate", "--certify", "--policy", f"{rules}:idle"]) == 2
    assert "it takes no --policy" in capsys.readouterr().err
