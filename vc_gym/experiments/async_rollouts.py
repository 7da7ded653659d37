"""PPO rollouts without lockstep: every worker steps as soon as it has its next action.

stable-baselines3 steps its ``SubprocVecEnv`` workers in lockstep: a step ends when the
slowest worker's does. A homing decision is not a fixed amount of work (a checked stop
stands for up to the task's 5 s, 50 steps of the task env), so in lockstep the other
worker idles through every stand (README, "Training"). Here each worker gets its next
action the moment its previous step returns; the rollout waits for the workers only
once, when every one of them has its ``n_steps`` transitions.

The rollout is the same as SB3's in what PPO learns from: ``n_steps`` consecutive
transitions per env, all taken with the policy as it was when the rollout began, time
limits bootstrapped with the value function. Only the order in which the workers'
transitions arrive depends on timing, and nothing depends on that order: each env
draws its actions from its own random stream (seeded from the model's seed, the env's
index and the decisions so far), so a run with the same seed gives the same policy
whatever the machine is doing.
"""

from __future__ import annotations

import math
import multiprocessing.connection
from typing import Any

import numpy as np

try:
    import torch as th
    from stable_baselines3 import PPO
    from stable_baselines3.common.distributions import DiagGaussianDistribution
    from stable_baselines3.common.utils import obs_as_tensor
    from stable_baselines3.common.vec_env import SubprocVecEnv
except ImportError as exc:  # pragma: no cover - the [rl] extra is what installs them
    raise ImportError("async rollouts need stable-baselines3: pip install 'vc_gym[rl]'") from exc

__all__ = ["AsyncRolloutPPO", "AsyncSubprocVecEnv", "WorkerDiedError"]

_LOG_SQRT_2PI = math.log(math.sqrt(2 * math.pi))


class WorkerDiedError(RuntimeError):
    """A worker process of an :class:`AsyncSubprocVecEnv` ended while it was stepping."""


class AsyncSubprocVecEnv(SubprocVecEnv):
    """``SubprocVecEnv`` whose workers can also be stepped one at a time.

    :meth:`send_step` starts one worker's step; :meth:`ready_steps` returns the steps
    that have finished, waiting for at least one. The lockstep ``step`` still works
    between rollouts (the warm start's demonstrations use it) as long as no single
    step is pending. Training uses it for the lockstep collector too: a worker that
    died is then a :class:`WorkerDiedError`, in lockstep as when stepped alone, and
    :meth:`close` does not hide it behind a ``BrokenPipeError``.
    """

    _DIED = (BrokenPipeError, ConnectionResetError, EOFError)

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

    def send_step(self, index: int, action: np.ndarray) -> None:
        """Start worker ``index``'s step with ``action``.

        Raises
        ------
        WorkerDiedError
            If the worker's process has ended.
        """
        try:
            self.remotes[index].send(("step", action))
        except self._DIED:
            raise WorkerDiedError(f"training worker {index} has ended") from None

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

    def ready_steps(self, pending: set[int]) -> list[tuple[int, tuple]]:
        """``[(index, (obs, reward, done, info))]`` of the pending workers that finished.

        Blocks until at least one has. A finished episode's ``info`` holds
        ``terminal_observation`` and ``obs`` is the next episode's first (as
        ``SubprocVecEnv.step`` gives them); the reset's info goes to ``reset_infos``.

        Raises
        ------
        WorkerDiedError
            If a pending worker's process ended (its env raised or it was killed).
        """
        by_remote = {id(self.remotes[i]): i for i in pending}
        ready = multiprocessing.connection.wait([self.remotes[i] for i in pending])
        out = []
        self.reset_infos = list(self.reset_infos)  # step_wait leaves a tuple
        for remote in ready:
            i = by_remote[id(remote)]
            try:
                obs, reward, done, info, reset_info = remote.recv()
            except self._DIED:
                raise WorkerDiedError(
                    f"training worker {i} ended while stepping (see its error above)"
                ) from None
            self.reset_infos[i] = reset_info
            out.append((i, (obs, float(reward), bool(done), info)))
        return out


class AsyncRolloutPPO(PPO):
    """PPO whose rollouts step an :class:`AsyncSubprocVecEnv`'s workers independently.

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

    def _act(self, obs: np.ndarray, env_index: int) -> tuple[np.ndarray, float, float]:
        """A sampled action, its value and log-probability for env ``env_index``'s
        observation ``obs``, the noise from that env's own stream.

        One env at a time, never a batch of whichever envs happen to be ready: a
        matrix product may round differently with another batch size, and then the
        policy would depend on timing. The arithmetic is SB3's ``get_distribution``,
        ``DiagGaussianDistribution.log_prob`` and ``predict_values``, operation for
        operation (the same numbers to the bit), in one pass through the networks and
        without building a ``torch.distributions`` object: it runs in the parent at every
        decision, on a core the workers share.
        """
        policy = self.policy
        if not isinstance(policy.action_dist, DiagGaussianDistribution):
            raise ValueError("async rollouts need a Gaussian policy over Box actions")
        with th.no_grad():
            features = policy.extract_features(obs_as_tensor(obs[None], self.device))
            if policy.share_features_extractor:
                latent_pi, latent_vf = policy.mlp_extractor(features)
            else:
                latent_pi = policy.mlp_extractor.forward_actor(features[0])
                latent_vf = policy.mlp_extractor.forward_critic(features[1])
            mean = policy.action_net(latent_pi)
            std = th.ones_like(mean) * policy.log_std.exp()
            gen = self._generators(self.env.num_envs)[env_index]
            noise = th.randn(mean.shape, generator=gen).to(mean.dtype)
            action = mean + std * noise
            # torch's Normal.log_prob, summed over the action's dimensions
            log_prob = -((action - mean) ** 2) / (2 * std**2) - std.log() - _LOG_SQRT_2PI
            value = float(policy.value_net(latent_vf)[0, 0])
        return action[0].cpu().numpy(), value, float(log_prob.sum(dim=1)[0])

    def collect_rollouts(self, env, callback, rollout_buffer, n_rollout_steps: int) -> bool:
        """Fill ``rollout_buffer`` with ``n_rollout_steps`` transitions per env, stepping
        every worker as soon as its previous step is back (SB3's contract otherwise)."""
        if not isinstance(env, AsyncSubprocVecEnv):
            return super().collect_rollouts(env, callback, rollout_buffer, n_rollout_steps)
        if self.use_sde or self.policy.squash_output:
            raise ValueError("async rollouts do not support gSDE or squashed actions")
        assert self._last_obs is not None, "No previous observation was provided"
        self.policy.set_training_mode(False)
        rollout_buffer.reset()
        callback.on_rollout_start()
        n_envs = env.num_envs
        low, high = self.action_space.low, self.action_space.high
        last_obs = np.array(self._last_obs)
        starts = np.array(self._last_episode_starts, dtype=np.float32)
        taken = np.zeros(n_envs, dtype=np.int64)
        rb = rollout_buffer
        # the transition each pending worker is computing: (action, value, log_prob)
        step_of: dict[int, tuple[np.ndarray, float, float]] = {}

        def launch(i: int) -> None:
            step_of[i] = self._act(last_obs[i], i)
            env.send_step(i, np.clip(step_of[i][0], low, high))

        # the callbacks see step t of every env once all have taken it, env by env, as
        # after a lockstep step: what they record does not depend on timing either
        ends: list[list[tuple[dict, bool] | None]] = [
            [None] * n_envs for _ in range(n_rollout_steps)
        ]
        base_timesteps = self.num_timesteps
        called = 0
        for i in range(n_envs):
            launch(i)
        while step_of:
            for i, (obs, reward, done, info) in env.ready_steps(set(step_of)):
                action, value, log_prob = step_of.pop(i)
                if done and info.get("TimeLimit.truncated", False):
                    # the episode was cut, not ended: bootstrap as SB3 does (its #633)
                    terminal = self.policy.obs_to_tensor(info["terminal_observation"])[0]
                    with th.no_grad():
                        reward += self.gamma * float(self.policy.predict_values(terminal)[0, 0])
                t = taken[i]
                rb.observations[t, i] = last_obs[i]
                rb.actions[t, i] = action
                rb.rewards[t, i] = reward
                rb.episode_starts[t, i] = starts[i]
                rb.values[t, i] = value
                rb.log_probs[t, i] = log_prob
                ends[t][i] = (info, done)
                taken[i] += 1
                last_obs[i] = obs
                starts[i] = float(done)
                if taken[i] < n_rollout_steps:
                    launch(i)
            while called < n_rollout_steps and all(e is not None for e in ends[called]):
                infos = [e[0] for e in ends[called]]
                dones = np.array([e[1] for e in ends[called]])
                called += 1
                self.num_timesteps = base_timesteps + called * n_envs
                callback.update_locals({"infos": infos, "dones": dones})
                if not callback.on_step():
                    self._drain(env, step_of)
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

    @staticmethod
    def _drain(env: AsyncSubprocVecEnv, step_of: dict[int, Any]) -> None:
        """Collect the steps still running, so the env can be used (or closed) again."""
        while step_of:
            for i, _ in env.ready_steps(set(step_of)):
                step_of.pop(i)
