"""``orbit-env train`` and ``orbit-env evaluate``: the agents of the orbit-raising environments."""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path
from typing import Any

from orbit_env.checks import check_int
from orbit_env.cli.common import (
    PROG,
    check_figure,
    check_output,
    flag,
    given,
    output_file,
    output_folder,
    positive_int,
)
from orbit_env.envs import DISPOSAL_YEARS, SOLAR_EVAL_SPLIT, SOLAR_SPLITS


def _cmd_train(args: argparse.Namespace) -> int:
    from orbit_env.agents.train import TrainingInterrupted, check_trainable, train

    if args.env is not None:  # the flag's value, named by the flag (train itself names the config file's key)
        check_trainable(args.env, f"--env {args.env}")
    try:
        result = train(
            args.config,
            args.out,
            total_timesteps=args.timesteps,
            seed=args.seed,
            num_envs=args.n_envs,
            env_id=args.env,
            resume=args.resume,
            force=args.force,
            progress=not args.no_progress,
        )
    except TrainingInterrupted as stop:
        typed = [("--config", args.config), ("--timesteps", args.timesteps), ("--seed", args.seed)]
        typed += [("--n-envs", args.n_envs), ("--env", args.env), ("--out", args.out), ("--resume", stop.checkpoint)]
        again = " ".join(f"{option} {shlex.quote(str(value))}" for option, value in typed if value is not None)
        if Path(args.out, "model.zip").exists():  # an interrupted resume of a finished run replaces it again
            again += " --force"
        print(
            f"{PROG}: interrupted at {stop.timesteps:,} timesteps (the last whole rollout), saved in "
            f"{stop.checkpoint}; continue with:\n  {PROG} train {again}",
            file=sys.stderr,
        )
        return 130
    print(f"trained {result.trained} timesteps in {result.seconds:.0f} s ({result.timesteps} in all)")
    print(f"model: {result.model_path}  (tensorboard --logdir {result.log_dir})")
    if result.best_model_path is not None:
        print(f"best on the validation episodes: {result.best_model_path}")
    return 0


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from orbit_env.agents.evaluate import (
        ALGORITHMS,
        all_policies,
        check_env_id,
        evaluate,
        format_table,
        paired_difference,
        plot_returns,
        write_returns,
    )

    def say(name: str) -> None:
        if not args.json:
            print(f"  running {name} ...", file=sys.stderr)

    def warn(message: str) -> None:
        print(f"{PROG}: warning: {message}", file=sys.stderr)

    from orbit_env.envs import SOLAR_ENV_IDS

    check_int(args.seed, "seed", low=0)  # before the model's load and the DP's solve
    if args.no_dp and not args.certify:  # (--certify names --no-dp itself)
        dp_flags = [flag(name) for name in ("dp_lookahead", "dp_rollout") if given(args, name)]
        if dp_flags:
            raise ValueError(f"--no-dp leaves the DP policy out: it takes no {' or '.join(dp_flags)}")
    _solar_options(args, args.env in SOLAR_ENV_IDS)
    # (An empty file name is refused by the flag's type, `output_file`.)
    if args.plot is not None and not args.certify:
        check_figure(args.plot, "--plot", [("the model file of --model", args.model)])
    if args.returns is not None and not args.certify:
        check_output(args.returns, "--returns", [("the model file of --model", args.model), ("--plot", args.plot)])
    if args.certify:
        names = ("model", "plot", "no_dp", "returns", "name", "policy")
        refused = [flag(name) for name in names if given(args, name)]
        if refused:  # the certificate searches plans against the DP: no learned row, no returns to draw
            raise ValueError(f"--certify searches plans against the DP policy: it takes no {' or '.join(refused)}")
        return _certify(args, say)
    own = _own_policies(args.policy, args.env in SOLAR_ENV_IDS, args.name)
    if args.env in SOLAR_ENV_IDS:
        return _evaluate_solar(args, say, own)
    check_env_id(args.env)
    policies = all_policies(
        args.env,
        model_path=args.model,
        include_dp=not args.no_dp,
        progress=say,
        warn=warn,
        dp_lookahead=args.dp_lookahead,
        dp_rollout=args.dp_rollout,
        learned_name=args.name,
    )
    policies.update(own)  # (their names checked against every other row's by `_own_policies`)
    results, table = evaluate(args.env, policies, args.episodes, args.seed, progress=say)
    if args.plot is not None:
        plot_returns(results, args.env, args.plot)
    if args.returns is not None:
        write_returns(results, args.returns)
    # The learned agent against the best hand-coded policy, then against the optimum.
    learned = args.name or next((name for name in results if name in ALGORITHMS), "ppo")
    paired = {
        "paired_difference": paired_difference(results, name=learned),
        "paired_to_dp": paired_difference(results, name=learned, baseline="dp"),
    }
    own_pairs = _own_pairs(results, own, None)
    if args.json:
        out = {"env": args.env, "episodes": args.episodes, "seed": args.seed, **_yardsticks(args), "policies": table}
        out.update({key: pair for key, pair in paired.items() if pair is not None})
        if own:
            out["paired_policies"] = own_pairs
        print(json.dumps(out))
    else:
        found = [pair for pair in paired.values() if pair is not None]
        print(format_table(args.env, args.episodes, args.seed, table, [*found, *own_pairs]))
    return 0


def _own_policies(specs: list[str] | None, solar: bool, learned_name: str | None) -> dict[str, Any]:
    """``--policy``'s policies by row name (`orbit_env.agents.evaluate.load_policy`), loaded before any episode.

    A name that another row has (a rule's, the DP's, an algorithm's, ``--name``'s) is refused here, before
    the DP's solve.
    """
    from orbit_env.agents.evaluate import ALGORITHMS, load_policy, policy_order

    if solar:
        from orbit_env.agents.solar import registered_rules

        taken = {rule.name for rule in registered_rules()} | {"dp", *ALGORITHMS}
    else:
        taken = set(policy_order())
    own: dict[str, Any] = {}
    for spec in specs or []:
        name, policy = load_policy(spec)
        if name in own or name in taken or name == learned_name:
            raise ValueError(f"--policy {spec}: {name} is the name of another row; give the policy another name")
        own[name] = policy
    return own


def _own_pairs(results: Any, own: dict[str, Any], best_rule: str | None) -> list[dict[str, Any]]:
    """Each ``--policy`` row against the best hand-coded rule (``best_rule``; None: found) and the DP, paired."""
    from orbit_env.agents.evaluate import paired_difference

    pairs = [paired_difference(results, name=name, baseline=base) for name in own for base in (best_rule, "dp")]
    return [pair for pair in pairs if pair is not None]


def _solar_options(args: argparse.Namespace, solar: bool) -> None:
    """Refuse the options of one kind of env given for the other (they would do nothing); fill in the defaults."""
    only_solar = ("solar_split", "disposal_years", "workers")
    solar_flags = [flag(name) for name in only_solar if getattr(args, name) is not None]
    if not solar and solar_flags:
        verb = "applies" if len(solar_flags) == 1 else "apply"
        raise ValueError(
            f"{', '.join(solar_flags)} {verb} to the solar task only (OrbitRaisingSolar-v0 and its continuous twin), "
            f"not to {args.env}"
        )
    if solar and args.dp_lookahead is not None:
        raise ValueError("--dp-lookahead applies to the known-density envs; the solar DP's policy looks a month ahead")
    args.solar_split = SOLAR_EVAL_SPLIT if args.solar_split is None else args.solar_split
    args.disposal_years = DISPOSAL_YEARS if args.disposal_years is None else args.disposal_years
    args.dp_lookahead = 1 if args.dp_lookahead is None else args.dp_lookahead


def _yardsticks(args: argparse.Namespace, *, lookahead: bool = True) -> dict[str, Any]:
    """What made the rows of a JSON result that its reader cannot see: which DP policy, which model."""
    dp = {"lookahead": args.dp_lookahead, "rollout": args.dp_rollout} if lookahead else {"rollout": args.dp_rollout}
    return {"dp_policy": None if args.no_dp else dp, "model": args.model if args.model is not None else "shipped"}


def _evaluate_solar(args: argparse.Namespace, say: Any, own: dict[str, Any]) -> int:
    """``evaluate --env OrbitRaisingSolar-v0``: the operators' rules and the per-episode optimum on a split."""
    from orbit_env.agents.evaluate import (
        format_table,
        load_model,
        paired_difference,
        plot_returns,
        policy_width,
        summarize,
        write_returns,
    )
    from orbit_env.agents.solar import evaluate_solar, solar_report
    from orbit_env.envs import SOLAR_CONTINUOUS_ENV_ID

    # The shipped PPO, or --model's; loaded (and its spaces checked) before the DPs' minutes.
    loaded = load_model(args.env, args.model, warn=lambda text: print(f"{PROG}: warning: {text}", file=sys.stderr))
    learned = {} if loaded is None else {args.name or loaded[0]: loaded[1]}
    learned.update(own)  # flown as the learned agents are, from the observations (names checked: `_own_policies`)
    evaluation = evaluate_solar(
        args.episodes,
        args.seed,
        solar_split=args.solar_split,
        disposal_years=args.disposal_years,
        include_dp=not args.no_dp,
        dp_rollout=args.dp_rollout,
        workers=args.workers,
        progress=say,
        learned=learned,
        continuous=args.env == SOLAR_CONTINUOUS_ENV_ID,
    )
    results = {name: flown.episodes() for name, flown in evaluation.flown.items()}
    if args.plot is not None:
        plot_returns(results, f"{args.env} ({args.solar_split} split)", args.plot)
    if args.returns is not None:
        write_returns(results, args.returns)
    table = summarize(results)
    report = solar_report(evaluation)
    # Episode by episode: the optimum against the best operators' rule (the task's headroom), the learned
    # agent against that rule and against the optimum. The JSON keys mean what they mean for every env:
    # paired_difference the learned agent less the best rule, paired_to_dp the learned agent less the DP.
    best_rule = max(evaluation.rules, key=lambda name: results[name].returns.mean())
    agent = next((name for name in learned if name not in own), None)
    pairs = {
        "paired_dp": paired_difference(results, name="dp", baseline=best_rule),
        "paired_difference": None if agent is None else paired_difference(results, name=agent, baseline=best_rule),
        "paired_to_dp": None if agent is None else paired_difference(results, name=agent, baseline="dp"),
    }
    paired = {key: pair for key, pair in pairs.items() if pair is not None}
    own_pairs = _own_pairs(results, own, best_rule)
    if args.json:
        out = {
            "env": args.env,
            "episodes": args.episodes,
            "seed": args.seed,
            "solar_split": args.solar_split,
            "disposal_years": args.disposal_years,
            **_yardsticks(args, lookahead=False),  # the solar DP's policy has no look-ahead setting
            "policies": {name: {**row, **report["policies"][name]} for name, row in table.items()},
            **{key: value for key, value in report.items() if key != "policies"},
        }
        out.update(paired)
        if own:
            out["paired_policies"] = own_pairs
        print(json.dumps(out))
        return 0
    title = f"{args.env} ({args.solar_split} split)"
    print(format_table(title, args.episodes, args.seed, table, [*paired.values(), *own_pairs]))
    width = policy_width(report["policies"])
    for name, row in report["policies"].items():
        print(
            f"  {name:<{width}} disposal burn on {row['disposal_share']:6.1%}, "
            f"non-compliant {row['noncompliant_share']:6.1%}, re-entered {row['reentered_share']:6.1%}"
        )
    print(f"thresholds tuned on the train split: {report['tuned']}")
    if "certificate" in report:
        cert = report["certificate"]
        print(
            f"certificate: the DP grid's estimate less the return its policy flew: mean {cert['mean_gap_days']:+.2f}, "
            f"largest {cert['max_gap_days']:+.2f} days; episodes where a rule beat the DP: {cert['beaten_by_a_rule']}"
        )
    return 0


def _certify(args: argparse.Namespace, say: Any) -> int:
    from orbit_env.agents.certify import certify, format_certificate
    from orbit_env.envs import SOLAR_ENV_IDS

    solar = {"solar_split": args.solar_split, "disposal_years": args.disposal_years}
    certificate = certify(
        args.env,
        args.episodes,
        args.seed,
        dp_lookahead=args.dp_lookahead,
        dp_rollout=args.dp_rollout,
        env_kwargs=solar if args.env in SOLAR_ENV_IDS else None,
        workers=args.workers,
        progress=say,
    )
    summary = certificate.summary()
    print(json.dumps(summary) if args.json else format_certificate(summary))
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from orbit_env.agents.sweep import SweepInterrupted, format_table, starts_ray, sweep

    if args.cpus is not None and not starts_ray(args.address):
        raise ValueError(
            f"--cpus sets the CPUs of a Ray the sweep starts (no --address, or --address local); --address "
            f"{args.address} joins a running Ray, which has its own: leave --cpus out"
        )
    algos = [a.strip() for a in args.algos.split(",") if a.strip()]
    try:
        result = sweep(
            args.env,
            algos,
            args.seeds,
            args.timesteps,
            args.out,
            address=args.address,
            episodes=args.episodes,
            include_dp=not args.no_dp,
            cpus=args.cpus,
            workers=args.workers,
            progress=lambda text: print(f"  {text} ...", file=sys.stderr),
        )
    except SweepInterrupted as stopped:
        print(f"orbit-env sweep: {stopped}", file=sys.stderr)
        return 1
    split = result.get("solar_split")
    print(format_table(args.env if split is None else f"{args.env} ({split} split)", result["table"], args.timesteps))
    print(
        f"{len(result['trials'])} trials on {result['cores']} cores in {result['sweep_wall_s']:.0f} s; "
        f"{args.out}/results.json"
    )
    return 0


def _cmd_curves(args: argparse.Namespace) -> int:
    from orbit_env.agents.curves import curves, format_curves, plot_curves

    algos = [a.strip() for a in args.algos.split(",") if a.strip()]
    if args.plot is not None:
        check_figure(args.plot, "--plot")
    result = curves(
        args.env,
        algos,
        args.seeds,
        args.timesteps,
        args.every,
        args.out,
        episodes=args.episodes,
        workers=args.workers,
        progress=lambda text: print(f"  {text} ...", file=sys.stderr),
    )
    if args.plot is not None:
        plot_curves(result, args.plot)
    print(json.dumps(result) if args.json else format_curves(result))
    return 0


def _row_name(text: str) -> str:
    """The argparse type of a table row's name: not blank (the row would have no name to read)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"a blank name ({text!r}); give the row a name")
    return text


def add_parsers(sub: Any) -> None:
    """The ``train``, ``evaluate``, ``sweep`` and ``curves`` commands."""
    tr = sub.add_parser("train", help="train PPO on the vector environment (config file: agents/ppo.toml)")
    tr.add_argument("--config", metavar="TOML", help="hyperparameter file (default: the shipped agents/ppo.toml)")
    tr.add_argument(
        "--out",
        type=output_folder,
        default="runs/ppo",
        metavar="DIR",
        help="logs, checkpoints, model.zip (default runs/ppo)",
    )
    tr.add_argument(
        "--timesteps", type=positive_int, metavar="N", help="override total_timesteps (rounded up to whole rollouts)"
    )
    tr.add_argument("--seed", type=int, metavar="S", help="override the config's seed")
    tr.add_argument(
        "--n-envs", type=positive_int, metavar="N", help="override num_envs, the satellites stepped together"
    )
    tr.add_argument("--env", metavar="ID", help="override env_id (the config's [env] keywords still apply)")
    tr.add_argument("--resume", metavar="ZIP", help="continue from a checkpoint (DIR/checkpoints/rl_model_N_steps.zip)")
    tr.add_argument(
        "--force",
        action="store_true",
        help="start over in --out, deleting a run there (finished or not: its model, checkpoints and scores); "
        "otherwise it is kept",
    )
    tr.add_argument("--no-progress", action="store_true", help="no progress bar")
    tr.set_defaults(func=_cmd_train)

    from orbit_env.agents import EVAL_EPISODES, EVAL_SEED

    ev = sub.add_parser("evaluate", help="every policy on the same seeded episodes: when does a burn pay off?")
    ev.add_argument("--env", default="OrbitRaising-v0", metavar="ID", help="environment id (default OrbitRaising-v0)")
    ev.add_argument(
        "--episodes", type=positive_int, default=EVAL_EPISODES, metavar="N", help=f"episodes (default {EVAL_EPISODES})"
    )
    ev.add_argument(
        "--seed", type=int, default=EVAL_SEED, metavar="S", help=f"seed of the episodes (default {EVAL_SEED})"
    )
    ev.add_argument(
        "--model",
        metavar="ZIP",
        help="a Stable-Baselines3 model (PPO, A2C, DQN, SAC, TD3; default: the shipped PPO of the environment); "
        "a policy of your own in Python: docs/how-to/score-a-policy.md",
    )
    ev.add_argument(
        "--name",
        type=_row_name,
        metavar="ROW",
        help="the learned agent's row (default: its algorithm, ppo, a2c, ...): two models of one algorithm "
        "side by side, each run under its own name",
    )
    ev.add_argument(
        "--policy",
        action="append",
        metavar="FILE.py:NAME",
        help="a policy of your own scored beside the others, its row named NAME (or MODULE:NAME): an object with "
        "Stable-Baselines3's predict, a class of one made with no arguments, or a function observations -> "
        "actions (docs/how-to/score-a-policy.md); repeatable",
    )
    ev.add_argument("--no-dp", action="store_true", help="skip the dynamic-programming optimum")
    ev.add_argument(
        "--dp-lookahead",
        type=int,
        choices=(1, 2),
        help="steps the DP policy takes exactly before reading its grid (default 1; 2 is closer to the optimum; "
        "not the solar task, whose DP policy looks one month ahead)",
    )
    ev.add_argument(
        "--dp-rollout",
        action="store_true",
        help="the DP row is the rollout policy on the DP: certified, slower (see docs/dp.md; "
        "the solar task: its first months decided by flying every burn, docs/solar-task.md)",
    )
    ev.add_argument(
        "--certify",
        action="store_true",
        help="instead, search for plans that beat the DP policy on the episodes' starts; report the gap found",
    )
    ev.add_argument(
        "--solar-split",
        choices=SOLAR_SPLITS,
        help=f"the solar task: the record's split the missions are drawn from (default {SOLAR_EVAL_SPLIT}; "
        "train: cycles 19-23, test: cycles 24-25)",
    )
    ev.add_argument(
        "--disposal-years",
        type=float,
        metavar="Y",
        help=f"the solar task: the disposal rule, re-entry within Y years of the mission's end "
        f"(default {DISPOSAL_YEARS:g})",
    )
    ev.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="the solar task: processes solving the DPs, also with --certify (default: cores)",
    )
    ev.add_argument("--json", action="store_true", help="print one JSON object")
    ev.add_argument("--plot", type=output_file, metavar="PNG", help="box plot of the returns")
    ev.add_argument(
        "--returns",
        type=output_file,
        metavar="CSV",
        help="every episode's return, a column per policy (the paired differences from them, episode by episode)",
    )
    ev.set_defaults(func=_cmd_evaluate)

    sw = sub.add_parser("sweep", help="algorithms x seeds as Ray Tune trials: a table of baselines with error bars")
    sw.add_argument("--env", default="OrbitRaising-v0", metavar="ID", help="environment id (default OrbitRaising-v0)")
    sw.add_argument("--algos", default="ppo,a2c", metavar="A,B", help="ppo, a2c, dqn, sac, td3, ppo_recipe")
    sw.add_argument("--seeds", type=positive_int, default=5, metavar="N", help="seeds 0..N-1 (default 5)")
    sw.add_argument("--timesteps", type=positive_int, default=100_000, metavar="T", help="per trial")
    sw.add_argument(
        "--out",
        type=output_folder,
        required=True,
        metavar="DIR",
        help="results.json, the models, Ray's state (resumable)",
    )
    sw.add_argument(
        "--address", metavar="RAY_ADDRESS", help="a running Ray cluster (default: a local Ray; local: a new one)"
    )
    sw.add_argument(
        "--episodes",
        type=positive_int,
        default=EVAL_EPISODES,
        metavar="N",
        help=f"evaluation episodes per trial (default {EVAL_EPISODES}; OrbitRaisingSolar-v0: test-split missions)",
    )
    sw.add_argument("--no-dp", action="store_true", help="no capture (skips the DP's solve)")
    sw.add_argument(
        "--cpus",
        type=positive_int,
        metavar="N",
        help="CPUs of the Ray the sweep starts (no --address, or --address local), one a trial (default: the cores)",
    )
    sw.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="OrbitRaisingSolar-v0: processes solving the references' DPs (default: cores)",
    )
    sw.set_defaults(func=_cmd_sweep)

    cu = sub.add_parser(
        "curves", help="the benchmark protocol: capture against steps over seeds, IQM with bootstrap CIs (resumable)"
    )
    cu.add_argument("--env", default="OrbitRaising-v0", metavar="ID", help="environment id (default OrbitRaising-v0)")
    cu.add_argument("--algos", default="ppo,ppo_recipe", metavar="A,B", help="ppo (SB3 defaults), ppo_recipe")
    cu.add_argument("--seeds", type=positive_int, default=5, metavar="N", help="seeds 0..N-1 (default 5)")
    cu.add_argument("--timesteps", type=positive_int, default=2_000_000, metavar="T", help="per run (default 2M)")
    cu.add_argument(
        "--every", type=positive_int, default=200_000, metavar="T", help="steps between points (default 200k)"
    )
    cu.add_argument(
        "--episodes",
        type=positive_int,
        default=EVAL_EPISODES,
        metavar="N",
        help=f"evaluation episodes, seed {EVAL_SEED} (default {EVAL_EPISODES})",
    )
    cu.add_argument("--workers", type=positive_int, default=1, metavar="N", help="runs at once (default 1)")
    cu.add_argument(
        "--out", type=output_folder, required=True, metavar="DIR", help="the runs' curves and results.json (resumable)"
    )
    cu.add_argument("--plot", type=output_file, metavar="PNG", help="draw the curves")
    cu.add_argument("--json", action="store_true", help="print results.json's content")
    cu.set_defaults(func=_cmd_curves)
