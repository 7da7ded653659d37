"""PPO rollouts without lockstep: every worker runs its own rollout with its own copy of
the policy.

stable-baselines3 steps its ``SubprocVecEnv`` workers in lockstep: a step ends when the
slowest worker's does. A homing decision is not a fixed amount of work (a checked stop
stands for up to the task's 5 s, 50 steps of the task env), so in lockstep the other
worker idles through every stand. Here each worker is sent the
policy's weights at the start of a rollout and takes its ``n_steps`` decisions on its
own, choosing each action itself: no worker waits for another, nor for the parent
process and a round trip through a pipe at every decision. The rollout waits for the
workers only once, when every one of them has its ``n_steps`` transitions.

The rollout is the same as SB3's in what PPO learns from: ``n_steps`` consecutive
transitions per env, all taken with the policy as it was when the rollout began, time
limits bootstrapped with the value function. Nothing depends on timing: each env draws
its actions from its own random stream (seeded from the model's seed, the env's index
and the decisions so far, kept by the model between rollouts), and an action is
computed one env at a time with SB3's arithmetic to the bit, so a run with the same seed
gives the same policy whatever the machine is doing, and the same as if the parent had
chosen every action. The callbacks see the transitions in lockstep order once the
rollout is in.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np

try:
    import cloudpickle
    import torch as th
    from stable_baselines3 import PPO
    from stable_baselines3.common.distributions import DiagGaussianDistribution
    from stable_baselines3.common.policies import ActorCriticPolicy
    from stable_baselines3.common.utils import obs_as_tensor
    from stable_baselines3.common.vec_env import SubprocVecEnv
except ImportError as exc:  # pragma: no cover - the [rl] extra is what installs them
    raise ImportError("async rollouts need stable-baselines3: pip install 'vc_gym[rl]'") from exc

__all__ = [
    "AsyncRolloutPPO",
    "AsyncSubprocVecEnv",
    "RolloutWorker",
    "WorkerDiedError",
    "policy_action",
]

_LOG_SQRT_2PI = math.log(math.sqrt(2 * math.pi))


class WorkerDiedError(RuntimeError):
    """A worker process of an :class:`AsyncSubprocVecEnv` ended while it was stepping."""


def policy_action(
    policy: ActorCriticPolicy, obs: np.ndarray, generator: th.Generator
) -> tuple[np.ndarray, float, float]:
    """A sampled action, its value and log-probability for one observation ``obs``, the
    noise drawn from ``generator``.

    One env at a time, never a batch of whichever envs happen to be ready: a matrix
    product may round differently with another batch size, and then the policy would
    depend on timing. The arithmetic is SB3's ``get_distribution``,
    ``DiagGaussianDistribution.log_prob`` and ``predict_values``, operation for operation
    (the same numbers to the bit), in one pass through the networks and without building
    a ``torch.distributions`` object.

    Raises
    ------
    ValueError
        If the policy is not a Gaussian over ``Box`` actions.
    """
    if not isinstance(policy.action_dist, DiagGaussianDistribution):
        raise ValueError("async rollouts need a Gaussian policy over Box actions")
    with th.no_grad():
        features = policy.extract_features(obs_as_tensor(obs[None], policy.device))
        if policy.share_features_extractor:
            latent_pi, latent_vf = policy.mlp_extractor(features)
        else:
            latent_pi = policy.mlp_extractor.forward_actor(features[0])
            latent_vf = policy.mlp_extractor.forward_critic(features[1])
        mean = policy.action_net(latent_pi)
        std = th.ones_like(mean) * policy.log_std.exp()
        noise = th.randn(mean.shape, generator=generator).to(mean.dtype)
        action = mean + std * noise
        # torch's Normal.log_prob, summed over the action's dimensions
        log_prob = -((action - mean) ** 2) / (2 * std**2) - std.log() - _LOG_SQRT_2PI
        value = float(policy.value_net(latent_vf)[0, 0])
    return action[0].cpu().numpy(), value, float(log_prob.sum(dim=1)[0])


class RolloutWorker(gym.Wrapper):
    """The env of one worker process, which can also run a whole rollout itself.

    :meth:`collect_rollout` is what :class:`AsyncSubprocVecEnv` calls in the worker (through
    SB3's ``env_method``); stepping and resetting are the wrapped env's.
    """

    def __init__(self, env: gym.Env):
        super().__init__(env)
        self._policy: ActorCriticPolicy | None = None
        self._policy_spec: bytes | None = None

    def collect_rollout(
        self,
        policy_spec: bytes,
        weights: dict[str, np.ndarray],
        generator_state: th.Tensor,
        obs: np.ndarray,
        start: float,
        n_steps: int,
        gamma: float,
    ) -> dict[str, Any]:
        """Take ``n_steps`` decisions from ``obs`` with the policy ``policy_spec`` (its
        class and constructor arguments, from the parent process) holding ``weights``.

        Each finished episode is reset at once, its last observation in the step's
        ``info["terminal_observation"]`` and a time limit bootstrapped with the value
        function (``gamma``), as SB3's worker and ``collect_rollouts`` do.

        Returns
        -------
        dict
            Per step: ``observations``, ``actions``, ``rewards``, ``episode_starts``,
            ``values``, ``log_probs``, ``infos``, ``dones``; then ``last_obs``,
            ``last_start``, the noise stream's ``generator_state`` and the last reset's
            ``reset_info``.
        """
        th.set_num_threads(1)  # a 64-wide MLP on one row: a second thread only spins
        if policy_spec != self._policy_spec:
            # sent by the parent process through its pipe, as SB3 sends the env itself
            cls, kwargs = cloudpickle.loads(policy_spec)
            self._policy, self._policy_spec = cls(**kwargs), policy_spec
        policy = self._policy
        policy.load_state_dict({k: th.from_numpy(v) for k, v in weights.items()})
        policy.set_training_mode(False)
        generator = th.Generator()
        generator.set_state(generator_state)
        low, high = self.action_space.low, self.action_space.high
        out: dict[str, Any] = {
            "observations": np.empty((n_steps, *np.shape(obs)), np.asarray(obs).dtype),
            "actions": np.empty((n_steps, *self.action_space.shape), np.float32),
            "rewards": np.empty(n_steps),
            "episode_starts": np.empty(n_steps),
            "values": np.empty(n_steps),
            "log_probs": np.empty(n_steps),
            "infos": [],
            "dones": np.empty(n_steps, bool),
        }
        reset_info = None
        for t in range(n_steps):
            action, value, log_prob = policy_action(policy, np.asarray(obs), generator)
            next_obs, reward, terminated, truncated, info = self.env.step(
                np.clip(action, low, high)
            )
            reward, done = float(reward), bool(terminated or truncated)
            info["TimeLimit.truncated"] = bool(truncated and not terminated)
            if done:
                info["terminal_observation"] = next_obs
                if info["TimeLimit.truncated"]:
                    # the episode was cut, not ended: bootstrap as SB3 does (its #633)
                    terminal = policy.obs_to_tensor(next_obs)[0]
                    with th.no_grad():
                        reward += gamma * float(policy.predict_values(terminal)[0, 0])
                next_obs, reset_info = self.env.reset()
            out["observations"][t] = obs
            out["actions"][t] = action
            out["rewards"][t] = reward
            out["episode_starts"][t] = start
            out["values"][t] = value
            out["log_probs"][t] = log_prob
            out["infos"].append(info)
            out["dones"][t] = done
            obs, start = next_obs, float(done)
        out.update(
            last_obs=obs,
            last_start=start,
            generator_state=generator.get_state(),
            reset_info=reset_info,
        )
        return out


class _WithRolloutWorker:
    """``env_fn`` whose env is wrapped in :class:`RolloutWorker` (picklable, for the
    worker processes)."""

    def __init__(self, env_fn):
        self.env_fn = env_fn

    def __call__(self) -> RolloutWorker:
        return RolloutWorker(self.env_fn())


class AsyncSubprocVecEnv(SubprocVecEnv):
    """``SubprocVecEnv`` whose workers can also run a whole rollout on their own.

    :meth:`collect_rollouts` sends every worker the policy and its rollout's start and
    returns their transitions. The lockstep ``step`` still works between rollouts (the
    warm start's demonstrations use it), and training uses this class for the lockstep
    collector too: a worker that died is then a :class:`WorkerDiedError`, in lockstep as
    in a rollout of its own, and :meth:`close` does not hide it behind a
    ``BrokenPipeError``.
    """

    _DIED = (BrokenPipeError, ConnectionResetError, EOFError)

    def __init__(self, env_fns, start_method: str | None = None):
        super().__init__([_WithRolloutWorker(fn) for fn in env_fns], start_method)

    def step_async(self, actions: np.ndarray) -> None:
        """SB3's lockstep step; a worker that has ended is a :class:`WorkerDiedError`."""
        try:
            super().step_async(actions)
        except self._DIED:
            raise WorkerDiedError("a training worker has ended (see its error above)") from None

    def step_wait(self):
        """SB3's lockstep step; a worker that ended while stepping is a
        :class:`WorkerDiedError`."""
        try:
            return super().step_wait()
        except self._DIED:
            self.waiting = False
            raise WorkerDiedError(
                "a training worker ended while stepping (see its error above)"
            ) from None

    def collect_rollouts(self, requests: list[tuple]) -> list[dict[str, Any]]:
        """Run :meth:`RolloutWorker.collect_rollout` with ``requests[i]`` (its arguments)
        in every worker ``i`` at once; their results, in worker order.

        Raises
        ------
        WorkerDiedError
            If a worker's process ended (its env raised or it was killed).
        """
        if len(requests) != self.num_envs:
            raise ValueError(f"one request per worker ({self.num_envs}), got {len(requests)}")
        for i, (remote, request) in enumerate(zip(self.remotes, requests, strict=True)):
            try:
                remote.send(("env_method", ("collect_rollout", request, {})))
            except self._DIED:
                raise WorkerDiedError(f"training worker {i} has ended") from None
        results = []
        for i, remote in enumerate(self.remotes):
            try:
                results.append(remote.recv())
            except self._DIED:
                raise WorkerDiedError(
                    f"training worker {i} ended while stepping (see its error above)"
                ) from None
        self.reset_infos = [
            r["reset_info"] if r["reset_info"] is not None else old
            for r, old in zip(results, self.reset_infos, strict=True)
        ]
        return results

    def close(self) -> None:
        """Close every worker; one that already ended is skipped (its error stays the
        one the caller sees)."""
        if self.closed:
            return
        for remote in self.remotes:
            try:
                remote.send(("close", None))
            except self._DIED:
                pass
        for process in self.processes:
            process.join()
        self.closed = True


class AsyncRolloutPPO(PPO):
    """PPO whose rollouts each worker of an :class:`AsyncSubprocVecEnv` runs on its own.

    Everything else is SB3's PPO (the update, saving, loading: a saved model is an
    ordinary PPO ``model.zip``). With any other ``VecEnv`` it collects as PPO does.
    Needs a Gaussian policy over a ``Box`` action space without gSDE (the homing
    agent's).
    """

    def _excluded_save_params(self) -> list[str]:
        # the per-env random streams are not saved (a file we read never unpickles)
        return [*super()._excluded_save_params(), "_env_generators"]

    def _generators(self, n_envs: int) -> list[th.Generator]:
        gens = getattr(self, "_env_generators", None)
        if gens is None or len(gens) != n_envs:
            seed = 0 if self.seed is None else int(self.seed)
            gens = []
            for i in range(n_envs):
                entropy = [seed, i, int(self.num_timesteps)]
                state = np.random.SeedSequence(entropy).generate_state(2, np.uint32)
                gens.append(th.Generator().manual_seed(int(state[0]) << 32 | int(state[1])))
            self._env_generators = gens
        return gens

    def collect_rollouts(self, env, callback, rollout_buffer, n_rollout_steps: int) -> bool:
        """Fill ``rollout_buffer`` with ``n_rollout_steps`` transitions per env, every
        worker running its own (SB3's contract otherwise)."""
        if not isinstance(env, AsyncSubprocVecEnv):
            return super().collect_rollouts(env, callback, rollout_buffer, n_rollout_steps)
        if self.use_sde or self.policy.squash_output:
            raise ValueError("async rollouts do not support gSDE or squashed actions")
        if not isinstance(self.policy.action_dist, DiagGaussianDistribution):
            raise ValueError("async rollouts need a Gaussian policy over Box actions")
        assert self._last_obs is not None, "No previous observation was provided"
        self.policy.set_training_mode(False)
        rollout_buffer.reset()
        callback.on_rollout_start()
        n_envs = env.num_envs
        gens = self._generators(n_envs)
        spec = cloudpickle.dumps((type(self.policy), self.policy._get_constructor_parameters()))
        weights = {k: v.detach().cpu().numpy() for k, v in self.policy.state_dict().items()}
        last_obs = np.array(self._last_obs)
        starts = np.array(self._last_episode_starts, dtype=np.float32)
        rollouts = env.collect_rollouts(
            [
                (
                    spec,
                    weights,
                    gens[i].get_state(),
                    last_obs[i],
                    float(starts[i]),
                    n_rollout_steps,
                    float(self.gamma),
                )
                for i in range(n_envs)
            ]
        )
        rb = rollout_buffer
        for i, r in enumerate(rollouts):
            gens[i].set_state(r["generator_state"])
            for key in (
                "observations",
                "actions",
                "rewards",
                "episode_starts",
                "values",
                "log_probs",
            ):
                getattr(rb, key)[:, i] = r[key]
            last_obs[i], starts[i] = r["last_obs"], r["last_start"]
        # the callbacks see step t of every env, env by env, as after a lockstep step
        base_timesteps = self.num_timesteps
        for t in range(n_rollout_steps):
            infos = [r["infos"][t] for r in rollouts]
            dones = np.array([r["dones"][t] for r in rollouts])
            self.num_timesteps = base_timesteps + (t + 1) * n_envs
            callback.update_locals({"infos": infos, "dones": dones})
            if not callback.on_step():
                return False
            self._update_info_buffer(infos, dones)
        rb.pos, rb.full = n_rollout_steps, True
        self._last_obs = last_obs
        self._last_episode_starts = starts
        with th.no_grad():
            values = self.policy.predict_values(obs_as_tensor(last_obs, self.device))
        rollout_buffer.compute_returns_and_advantage(last_values=values, dones=starts)
        callback.update_locals({"infos": [], "dones": starts})
        callback.on_rollout_end()
        return True
