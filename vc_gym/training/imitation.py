"""Warm start of a learned agent from the scripted agent's demonstrations (behaviour cloning).

``vc-gym train --demo-episodes N`` first lets :class:`~vc_gym.agents.HomingFeatureExpert`
(the paper's homing rule on ``vc_gym/Homing-v0``'s features) home ``N`` times in the
training envs, then fits the PPO policy's mean action to the expert's actions and its value
to the discounted returns of those episodes, and only then starts PPO. PPO from scratch
must first discover walking home and stopping by chance; the clone starts where the
scripted agent is and PPO improves on it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from tqdm import tqdm

from vc_gym.envs.homing import STOP_THRESHOLD
from vc_gym.training.feature_expert import HomingFeatureExpert

__all__ = ["Demonstrations", "clone_behaviour", "collect_demonstrations"]


@dataclass(frozen=True)
class Demonstrations:
    """Decisions of finished expert episodes.

    Attributes
    ----------
    observations : ndarray, shape (n, d)
        Feature vectors the expert saw.
    actions : ndarray, shape (n, 3)
        Its ``(walk, turn, stop)`` actions.
    returns : ndarray, shape (n,)
        Discounted return from each decision to the end of its episode.
    episodes : list of dict
        ``{"return", "decisions", "stop_error_m", "success"}`` per episode.
    """

    observations: np.ndarray
    actions: np.ndarray
    returns: np.ndarray
    episodes: list[dict[str, Any]]

    @property
    def success_rate(self) -> float:
        """Share of the episodes that stopped within the success radius."""
        return float(np.mean([e["success"] for e in self.episodes])) if self.episodes else 0.0


def collect_demonstrations(
    venv: Any,
    expert: HomingFeatureExpert,
    episodes: int,
    gamma: float,
    progress: bool = False,
) -> Demonstrations:
    """Run ``expert`` in a stable-baselines3 ``VecEnv`` until ``episodes`` episodes ended.

    Episodes still running when the last one ends are dropped (their returns are
    unknown). The env is left mid-episode; a following ``learn`` resets it.

    Parameters
    ----------
    venv : VecEnv
        ``vc_gym/Homing-v0`` envs (auto-resetting).
    expert : HomingFeatureExpert
        The demonstrator.
    episodes : int
        Finished episodes to collect, >= 1.
    gamma : float
        Discount of the returns (the agent's).
    progress : bool
        Show a progress bar.
    """
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ValueError(f"episodes must be an int >= 1, got {episodes!r}")
    if not 0 < gamma <= 1:
        raise ValueError(f"gamma must be in (0, 1], got {gamma!r}")
    n = venv.num_envs
    running: list[list[tuple[np.ndarray, np.ndarray, float]]] = [[] for _ in range(n)]
    obs_out, act_out, ret_out, done_eps = [], [], [], []
    obs = venv.reset()
    with tqdm(total=episodes, desc="demonstrations", unit="ep", disable=not progress) as bar:
        while len(done_eps) < episodes:
            actions = expert.predict(obs)
            next_obs, rewards, dones, infos = venv.step(actions)
            for i in range(n):
                running[i].append((obs[i], actions[i], float(rewards[i])))
                if not dones[i] or len(done_eps) >= episodes:
                    continue
                steps, running[i] = running[i], []
                g, returns = 0.0, []
                for _, _, r in reversed(steps):
                    g = r + gamma * g
                    returns.append(g)
                obs_out.extend(s[0] for s in steps)
                act_out.extend(s[1] for s in steps)
                ret_out.extend(reversed(returns))
                info = infos[i]
                done_eps.append(
                    {
                        "return": float(sum(s[2] for s in steps)),
                        "decisions": len(steps),
                        "stop_error_m": float(info.get("stop_error_m", float("nan"))),
                        "success": bool(info.get("success", False)),
                    }
                )
                bar.update(1)
            obs = next_obs
    return Demonstrations(
        np.asarray(obs_out, np.float32),
        np.asarray(act_out, np.float32),
        np.asarray(ret_out, np.float32),
        done_eps,
    )


def clone_behaviour(
    policy: Any,
    demos: Demonstrations,
    updates: int = 3000,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    log_std: float = -1.2,
    seed: int = 0,
) -> dict[str, float]:
    """Fit an SB3 ``ActorCriticPolicy`` to demonstrations (in place).

    Minimises the squared error of the policy's mean action against the expert's plus
    half the squared error of its value against the returns, with Adam over ``updates``
    shuffled minibatches. The stop output's errors are weighted so that stop and walk
    decisions count equally: the expert stops once per episode, and an unweighted fit
    learns never to stop. Afterwards the Gaussian's log standard deviation is set to
    ``log_std`` for every action: the clone keeps its mean, and PPO explores around it.
    The stop output is a threshold at 0.5 on a mean near -1 while walking, so the
    default σ ≈ 0.3 almost never stops by accident (σ ≈ 0.6, PPO's usual start, would
    stop about once per 160 walking decisions).

    Returns
    -------
    dict
        ``action_mse`` (unweighted), ``value_mse`` and ``stop_accuracy`` (share of the
        demonstrations whose stop decision the clone repeats), over all demonstrations.
    """
    import torch

    if len(demos.actions) == 0:
        raise ValueError("no demonstrations to clone")
    for name, v in (("updates", updates), ("batch_size", batch_size)):
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise ValueError(f"{name} must be an int >= 1, got {v!r}")
    device = policy.device
    obs = torch.as_tensor(demos.observations, device=device)
    act = torch.as_tensor(demos.actions, device=device)
    ret = torch.as_tensor(demos.returns, device=device)
    stops = act[:, -1] > STOP_THRESHOLD
    weights = torch.ones_like(act)
    share = float(stops.float().mean())
    if 0.0 < share < 1.0:  # stop and walk decisions weigh the same in total
        weights[:, -1] = torch.where(stops, 0.5 / share, 0.5 / (1.0 - share))
    gen = torch.Generator().manual_seed(int(seed))
    opt = torch.optim.Adam(policy.parameters(), lr=float(learning_rate))
    policy.set_training_mode(True)
    n, done = len(act), 0
    while done < updates:
        order = torch.randperm(n, generator=gen)
        for start in range(0, n, batch_size):
            idx = order[start : start + batch_size]
            mean = policy.get_distribution(obs[idx]).distribution.mean
            value = policy.predict_values(obs[idx]).flatten()
            a_loss = (weights[idx] * (mean - act[idx]) ** 2).mean()
            v_loss = ((value - ret[idx]) ** 2).mean()
            opt.zero_grad()
            (a_loss + 0.5 * v_loss).backward()
            opt.step()
            done += 1
            if done >= updates:
                break
    policy.set_training_mode(False)
    with torch.no_grad():
        policy.log_std.fill_(float(log_std))
        mean = policy.get_distribution(obs).distribution.mean
        value = policy.predict_values(obs).flatten()
        return {
            "action_mse": float(((mean - act) ** 2).mean()),
            "value_mse": float(((value - ret) ** 2).mean()),
            "stop_accuracy": float(((mean[:, -1] > STOP_THRESHOLD) == stops).float().mean()),
        }
