"""The agents' commands refuse what they cannot do, in one line naming the flag (a review of the command line).

Each test failed before its fix.
"""

import pytest

from orbit_env.cli import main


def one_line_error(capsys) -> str:
    """The error a command printed: one line on stderr, no traceback."""
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


# --------------------------------------------------------------------------------------
# A negative seed, and a flag's value blamed on the flag
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env", ["OrbitRaising-v0", "OrbitRaisingSolar-v0"])
def test_evaluate_refuses_a_negative_seed_in_one_line(capsys, env):
    # Gymnasium's "Seed must be greater or equal to zero" had ended the command in a traceback.
    assert main(["evaluate", "--env", env, "--no-dp", "--episodes", "2", "--seed", "-1"]) == 2
    assert "--seed -1 is out of range; allowed: an integer at least 0" in one_line_error(capsys)
    assert main(["evaluate", "--certify", "--episodes", "2", "--seed", "-1"]) == 2
    assert "--seed -1 is out of range" in one_line_error(capsys)


def test_the_api_refuses_a_negative_seed_naming_it():
    from orbit_env.agents.evaluate import hand_coded_policies, run_episodes

    with pytest.raises(ValueError, match=r"^seed=-1 is out of range; allowed: an integer at least 0$"):
        run_episodes("OrbitRaising-v0", hand_coded_policies("OrbitRaising-v0")["never"], 2, -1)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--seed", "-1"], "--seed -1 is out of range; allowed: an integer at least 0"),
        (["--env", "Nope-v0"], "--env Nope-v0 is not an orbit_env environment; allowed: OrbitRaising-v0"),
    ],
)
def test_train_blames_a_flags_value_on_the_flag_not_on_the_config_file(tmp_path, capsys, flags, message):
    out = tmp_path / "run"
    assert main(["train", "--out", str(out), "--no-progress", *flags]) == 2
    err = one_line_error(capsys)
    assert message in err and "ppo.toml" not in err
    assert not out.exists()


def test_train_names_its_arguments_as_the_caller_gave_them(tmp_path):
    from orbit_env.agents.train import train

    with pytest.raises(ValueError, match=r"^seed=-1 is out of range"):
        train(out_dir=tmp_path / "run", seed=-1, progress=False)
    with pytest.raises(ValueError, match=r"^env_id='Nope-v0' is not an orbit_env environment"):
        train(out_dir=tmp_path / "run", env_id="Nope-v0", progress=False)
    assert not (tmp_path / "run").exists()
