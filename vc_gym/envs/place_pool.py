"""Several learned places as one env: each episode happens in one of them, drawn at reset.

A learned agent trained in a single place (one learning phase, one atlas) learns that
place's quirks: how its spots' goodness looks near home, where its stops drift. Training
over a pool of places, each learned with another learning seed, asks it for what holds
in every place.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym.validation import check_action

__all__ = ["PlacePool"]


class PlacePool(gym.Env):
    """Envs of the same task in different places; every episode runs in one of them.

    ``reset(seed=...)`` draws the place uniformly from the pool with the pool's own
    ``np_random`` and resets that env with a seed drawn from it too, so a seeded reset
    gives the same place and the same episode every time. ``step`` and ``render`` go to
    the place of the current episode; ``info["place"]`` says which (its index in
    ``envs``). Every env must have the same observation and action spaces (the same
    task: e.g. ``vc_gym/Homing-v0`` with as many spots in every place).

    Parameters
    ----------
    envs : sequence of gymnasium.Env
        One env per place, at least one. The pool owns them: :meth:`close` closes all.

    Raises
    ------
    ValueError
        On an empty pool, something that is not an env, or spaces that differ; from
        ``reset``, for ``options`` that are not a dict (the place's env checks their
        keys); from ``step``, for an action that is not a finite real array of a
        ``Box`` action space's shape.
    """

    def __init__(self, envs: Sequence[gym.Env]):
        envs = list(envs)
        if not envs:
            raise ValueError("a PlacePool needs at least one env")
        for k, env in enumerate(envs):
            if not isinstance(env, gym.Env):
                raise ValueError(f"envs[{k}] must be a gymnasium.Env, got {type(env).__name__}")
            for name in ("observation_space", "action_space"):
                if getattr(env, name) != getattr(envs[0], name):
                    raise ValueError(
                        f"every place must have the same {name}: envs[{k}] has "
                        f"{getattr(env, name)}, envs[0] {getattr(envs[0], name)}"
                    )
        self.envs = envs
        self.observation_space = envs[0].observation_space
        self.action_space = envs[0].action_space
        self.metadata = dict(envs[0].metadata)
        self.render_mode = envs[0].render_mode
        self.place: int | None = None
        self._closed = False

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        if self._closed:
            raise RuntimeError("this PlacePool is closed")
        if options is not None and not isinstance(options, Mapping):
            # refused before a place is drawn; the place's env checks the keys
            raise ValueError(
                f"reset options must be a dict (or None), got {type(options).__name__}: "
                f"{options!r:.80}"
            )
        super().reset(seed=seed)
        self.place = int(self.np_random.integers(len(self.envs)))
        episode_seed = int(self.np_random.integers(2**31))
        obs, info = self.envs[self.place].reset(seed=episode_seed, options=options)
        return obs, {**info, "place": self.place}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        if self._closed:
            raise RuntimeError("this PlacePool is closed")
        if self.place is None:
            raise RuntimeError("call reset() before step()")
        if isinstance(self.action_space, spaces.Box):
            check_action(action, self.action_space.shape)  # the place's env may not check
        obs, reward, terminated, truncated, info = self.envs[self.place].step(action)
        return obs, reward, terminated, truncated, {**info, "place": self.place}

    def render(self) -> np.ndarray | None:
        return self.envs[0 if self.place is None else self.place].render()

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            for env in self.envs:
                env.close()
