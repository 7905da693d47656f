"""PPO on OrbitRaising-v0 in one file, in the manner of CleanRL's ``ppo.py``.

Discrete PPO (Schulman et al. 2017) with GAE, the clipped objective, a value loss, an
entropy bonus, per-minibatch advantage normalisation and a linearly annealed learning
rate, on the numpy vector environment (``gymnasium.make_vec``). The hyperparameters are
those of the project's Stable-Baselines3 recipe, ``agents/ppo.toml`` (see
docs/how-to/train.md), and so are its training methods:

* the log features, ln(L / 365 d) and ln(1 - clock), appended to the observation by
  `orbit_env.envs.wrappers.LogFeaturesVectorObservation`;
* gamma = 1 with the mission's end terminal (the reward counts days within the mission);
* the potential-based shaping r + Phi(s') - Phi(s), Phi the return of never burning
  again (`orbit_env.agents.shaping.outlook`; the optimal policy is unchanged), and the
  end of an episode after the step from a decided state (tank empty, or the satellite
  outlives the mission), where the shaped optimal value is 0;
* a coast logit of +4 at the start (p(coast) = 0.95), rewards divided by the running
  standard deviation of the return (SB3's ``VecNormalize``).

At the end the greedy policy is scored as ``orbit-env evaluate`` scores every policy:
the same 1000 seeded missions, capture = (R - R_never) / (R_dp - R_never), with the
never-burn and DP baselines of `orbit_env.agents.evaluate`. It needs torch, numpy,
gymnasium and orbit_env (``orbit_env.agents.shaping`` imports Stable-Baselines3, which the
``train`` extra brings with torch)::

    python examples/cleanrl_ppo.py --total-timesteps 4000000 --save /tmp/ppo.pt
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np
import torch
from torch import nn
from torch.distributions.categorical import Categorical

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents.dp import DEFAULT_GRID, DPPolicy
from orbit_env.agents.evaluate import EVAL_EPISODES, EVAL_SEED, dp_policy, evaluate, format_table, hand_coded_policies
from orbit_env.agents.shaping import outlook
from orbit_env.envs.wrappers import LogFeaturesVectorObservation, log_features


def parse_args() -> argparse.Namespace:
    """The hyperparameters: ``agents/ppo.toml``'s, but for the budget."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--env-id", default="OrbitRaising-v0", help="a discrete orbit-raising environment")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--total-timesteps", type=int, default=4_000_000, help="environment steps to train")
    p.add_argument("--num-envs", type=int, default=64, help="satellites stepped together")
    p.add_argument("--num-steps", type=int, default=512, help="steps per environment per rollout")
    p.add_argument("--learning-rate", type=float, default=1e-3)
    p.add_argument("--anneal-start", type=float, default=0.5, help="share of the run after which the rate falls to 0")
    p.add_argument("--gamma", type=float, default=1.0)
    p.add_argument("--gae-lambda", type=float, default=0.95)
    p.add_argument("--num-minibatches", type=int, default=8)
    p.add_argument("--update-epochs", type=int, default=10)
    p.add_argument("--clip-coef", type=float, default=0.2)
    p.add_argument("--ent-coef", type=float, default=0.001)
    p.add_argument("--vf-coef", type=float, default=0.5)
    p.add_argument("--max-grad-norm", type=float, default=0.5)
    p.add_argument("--coast-logit", type=float, default=4.0, help="initial bias of the coast action's logit")
    p.add_argument("--shaping", action=argparse.BooleanOptionalAction, default=True, help="never-burn potential")
    p.add_argument("--end-decided", type=float, default=1.0, help="probability a decided step ends its episode")
    p.add_argument("--threads", type=int, default=1, help="torch's intra-op threads")
    p.add_argument("--save", metavar="PATH", help="save the final weights (torch state dict) here")
    p.add_argument("--eval-episodes", type=int, default=EVAL_EPISODES, help="evaluation missions")
    p.add_argument("--eval-seed", type=int, default=EVAL_SEED, help="seed of the evaluation missions")
    p.add_argument(
        "--dp-grid",
        type=int,
        help=f"states of a coarser DP, known density (default: orbit-env evaluate's, {DEFAULT_GRID[0]}); smoke tests",
    )
    args = p.parse_args()
    if args.end_decided > 0 and not args.shaping:
        p.error("--end-decided > 0 needs --shaping (the shaped optimal value of a decided state is 0)")
    return args


def layer_init(layer: nn.Linear, std: float = np.sqrt(2), bias_const: float = 0.0) -> nn.Linear:
    """Orthogonal weights, constant bias (CleanRL's and SB3's initialisation)."""
    nn.init.orthogonal_(layer.weight, std)
    nn.init.constant_(layer.bias, bias_const)
    return layer


class Agent(nn.Module):
    """Separate actor and critic, 64 x 64 tanh, on the observation and its log features."""

    def __init__(self, obs_dim: int, n_actions: int, coast_logit: float) -> None:
        super().__init__()
        self.critic = nn.Sequential(
            layer_init(nn.Linear(obs_dim, 64)),
            nn.Tanh(),
            layer_init(nn.Linear(64, 64)),
            nn.Tanh(),
            layer_init(nn.Linear(64, 1), std=1.0),
        )
        self.actor = nn.Sequential(
            layer_init(nn.Linear(obs_dim, 64)),
            nn.Tanh(),
            layer_init(nn.Linear(64, 64)),
            nn.Tanh(),
            layer_init(nn.Linear(64, n_actions), std=0.01),
        )
        with torch.no_grad():  # burns are rare decisions: start coasting with p = 0.95
            self.actor[-1].bias[0] += coast_logit

    def get_value(self, x: torch.Tensor) -> torch.Tensor:
        """The critic's value of a batch of observations."""
        return self.critic(x)

    def get_action_and_value(self, x: torch.Tensor, action: torch.Tensor | None = None):
        """Sample (or score) actions: action, log-probability, entropy, value."""
        probs = Categorical(logits=self.actor(x))
        if action is None:
            action = probs.sample()
        return action, probs.log_prob(action), probs.entropy(), self.critic(x)

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """SB3's protocol, for `orbit_env.agents.evaluate`: the likeliest action for raw (n, 7) observations."""
        with torch.no_grad():
            logits = self.actor(torch.as_tensor(log_features(observation)))
        return logits.argmax(dim=-1).numpy(), state


class ReturnScale:
    """Rewards divided by the running std of the discounted return, clipped to +-10 (SB3's VecNormalize)."""

    def __init__(self, num_envs: int, gamma: float) -> None:
        self.gamma, self.ret = gamma, np.zeros(num_envs)
        self.mean, self.var, self.count = 0.0, 1.0, 1e-4

    def __call__(self, reward: np.ndarray, ended: np.ndarray) -> np.ndarray:
        """Update the statistics with this step's returns; scale the rewards; restart ended returns."""
        self.ret = self.ret * self.gamma + reward
        mean, var, n = self.ret.mean(), self.ret.var(), self.ret.size
        delta, total = mean - self.mean, self.count + n
        self.mean += delta * n / total
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.count = total
        self.ret[ended] = 0.0
        return np.clip(reward / np.sqrt(self.var + 1e-8), -10.0, 10.0)


def main() -> None:
    """Train, save, and score the agent as ``orbit-env evaluate`` does."""
    args = parse_args()
    batch_size = args.num_envs * args.num_steps
    minibatch_size = batch_size // args.num_minibatches
    num_iterations = max(1, args.total_timesteps // batch_size)
    torch.manual_seed(args.seed)  # the networks and the sampled actions; rng: the rest, no global state
    torch.set_num_threads(args.threads)
    rng = np.random.default_rng(args.seed)

    # DISABLED: this loop restarts finished (and decided) episodes itself, in the step that ends them.
    envs = LogFeaturesVectorObservation(
        gym.make_vec(args.env_id, num_envs=args.num_envs, autoreset_mode=gym.vector.AutoresetMode.DISABLED)
    )
    if not isinstance(envs.single_action_space, gym.spaces.Discrete):
        raise SystemExit(f"{args.env_id} has continuous actions; this PPO is discrete")
    base = envs.unwrapped  # the task model and state give the shaping's potential
    if args.end_decided > 0 and (base.density.varies or np.ptp(base.density.scale_range) > 0):
        raise SystemExit("--end-decided needs a known, constant density: use --end-decided 0")
    agent = Agent(envs.single_observation_space.shape[0], int(envs.single_action_space.n), args.coast_logit)
    optimizer = torch.optim.Adam(agent.parameters(), lr=args.learning_rate, eps=1e-5)
    scale = ReturnScale(args.num_envs, args.gamma)

    obs = torch.zeros((args.num_steps, args.num_envs, *envs.single_observation_space.shape))
    actions = torch.zeros((args.num_steps, args.num_envs), dtype=torch.long)
    logprobs, rewards, dones, values = (torch.zeros((args.num_steps, args.num_envs)) for _ in range(4))

    start = time.time()
    global_step = 0
    next_obs_np, _ = envs.reset(seed=args.seed)
    next_obs, next_done = torch.as_tensor(next_obs_np), torch.zeros(args.num_envs)
    phi, decided = outlook(base.task, base.task_state)
    mission = np.zeros(args.num_envs)  # each episode's plain return so far: what evaluation scores
    finished: list[float] = []
    for iteration in range(1, num_iterations + 1):
        progress = (iteration - 1) / num_iterations
        decay = min(1.0, (1.0 - progress) / (1.0 - args.anneal_start)) if args.anneal_start < 1 else 1.0
        optimizer.param_groups[0]["lr"] = decay * args.learning_rate

        for step in range(args.num_steps):
            global_step += args.num_envs
            obs[step], dones[step] = next_obs, next_done
            with torch.no_grad():
                action, logprob, _, value = agent.get_action_and_value(next_obs)
            values[step], actions[step], logprobs[step] = value.flatten(), action, logprob

            next_obs_np, reward, terminated, truncated, _ = envs.step(action.numpy())
            ended = terminated | truncated  # the mission's end is terminal: no value past it
            phi_next, decided_next = outlook(base.task, base.task_state)
            shaped = reward + np.where(ended, 0.0, phi_next) - phi if args.shaping else reward
            mission += reward
            if args.end_decided > 0:  # coasting on from s' is optimal and earns Phi(s'): stop here
                cut = decided & ~ended & (rng.random(args.num_envs) < args.end_decided)
                mission += np.where(cut, phi_next, 0.0)
                ended |= cut
            if ended.any():
                finished.extend(mission[ended])
                mission[ended] = 0.0
                next_obs_np, _ = envs.reset(options={"reset_mask": ended})
                phi_next, decided_next = outlook(base.task, base.task_state)
            phi, decided = phi_next, decided_next
            rewards[step] = torch.as_tensor(scale(shaped, ended), dtype=torch.float32)
            next_obs, next_done = torch.as_tensor(next_obs_np), torch.as_tensor(ended, dtype=torch.float32)

        with torch.no_grad():  # GAE
            next_value = agent.get_value(next_obs).reshape(1, -1)
            advantages = torch.zeros_like(rewards)
            lastgaelam = 0
            for t in reversed(range(args.num_steps)):
                if t == args.num_steps - 1:
                    nextnonterminal, nextvalues = 1.0 - next_done, next_value
                else:
                    nextnonterminal, nextvalues = 1.0 - dones[t + 1], values[t + 1]
                delta = rewards[t] + args.gamma * nextvalues * nextnonterminal - values[t]
                advantages[t] = lastgaelam = delta + args.gamma * args.gae_lambda * nextnonterminal * lastgaelam
            returns = advantages + values

        b_obs = obs.reshape((-1, *envs.single_observation_space.shape))
        b_logprobs, b_actions = logprobs.reshape(-1), actions.reshape(-1)
        b_advantages, b_returns = advantages.reshape(-1), returns.reshape(-1)
        b_inds = np.arange(batch_size)
        clipfracs = []
        for _epoch in range(args.update_epochs):
            rng.shuffle(b_inds)
            for begin in range(0, batch_size, minibatch_size):
                mb = b_inds[begin : begin + minibatch_size]
                _, newlogprob, entropy, newvalue = agent.get_action_and_value(b_obs[mb], b_actions[mb])
                ratio = (newlogprob - b_logprobs[mb]).exp()
                clipfracs.append(((ratio - 1.0).abs() > args.clip_coef).float().mean().item())
                mb_adv = b_advantages[mb]
                mb_adv = (mb_adv - mb_adv.mean()) / (mb_adv.std() + 1e-8)
                pg_loss = torch.max(
                    -mb_adv * ratio, -mb_adv * torch.clamp(ratio, 1 - args.clip_coef, 1 + args.clip_coef)
                ).mean()
                v_loss = 0.5 * ((newvalue.view(-1) - b_returns[mb]) ** 2).mean()
                loss = pg_loss - args.ent_coef * entropy.mean() + v_loss * args.vf_coef
                optimizer.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), args.max_grad_norm)
                optimizer.step()

        recent = np.mean(finished[-500:]) if finished else float("nan")
        print(
            f"iteration {iteration}/{num_iterations}, step {global_step}: mission return {recent:.1f} "
            f"(last 500 training episodes), clipfrac {np.mean(clipfracs):.3f}, "
            f"{global_step / (time.time() - start):.0f} steps/s",
            flush=True,
        )
    train_seconds = time.time() - start
    envs.close()
    if args.save:
        torch.save(agent.state_dict(), args.save)
        print(f"weights saved to {args.save}")

    # Score the greedy policy as `orbit-env evaluate --env ENV` scores every policy.
    start = time.time()
    if args.dp_grid is None:
        dp = dp_policy(args.env_id)
    else:
        base_env = gym.make(args.env_id).unwrapped
        dp = DPPolicy(base_env.config, grid=(args.dp_grid, 1, 1), density_scale=base_env.density.nominal_scale)
    policies = {"never": hand_coded_policies(args.env_id)["never"], "dp": dp, "ppo": agent}
    _, table = evaluate(args.env_id, policies, args.eval_episodes, args.eval_seed)
    print(format_table(args.env_id, args.eval_episodes, args.eval_seed, table))
    print(
        f"capture {table['ppo']['capture']:.1%}: {global_step} timesteps, training {train_seconds:.0f} s, "
        f"evaluation {time.time() - start:.0f} s"
    )


if __name__ == "__main__":
    main()
