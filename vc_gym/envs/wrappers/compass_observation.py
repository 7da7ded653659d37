"""A wrapper that puts the visual compass, its atlas and a tracker inside the env."""

from __future__ import annotations

import math
import time
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from vc_gym.compass import Camera, CompassAtlas
from vc_gym.localization import Tracker, TrackerSpec, TrackerState, make_tracker
from vc_gym.poses import world_to_body

__all__ = ["CompassObservation"]

_BIG = np.float32(1e6)


class CompassObservation(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Adds what the robot's compass and tracker know to each observation.

    Every step, the wrapped env's head-camera frame, head pan and odometry go through
    a tracker (:mod:`vc_gym.localization`; default ``"grid"``: the paper's
    orientational grid filter, eq. 23-27, and translational filter, eq. 30-32, fed by
    the atlas of compasses learned at the training spots). Agents, including learned
    ones, then work from the compass, never from the true pose: nothing in the
    observation depends on ``info`` (tested).

    Observation keys added to the wrapped env's ``Dict`` (world frame of the atlas,
    home at the atlas' home position):

    * ``heading``: ``(cos θ̂, sin θ̂)`` of the estimated body heading (eq. 25);
    * ``heading_spread``: circular standard deviation of the heading belief, degrees
      (eq. 26-27);
    * ``position``: filtered position estimate ``τ̂`` in metres (eq. 32);
    * ``position_std``: the tracker's position uncertainty per axis, metres (capped
      at 100);
    * ``home_vector``: home as seen from the estimated pose, in the robot's frame
      (forward, left) in metres;
    * ``goodness``: normalised goodness ``L̂_i`` of each spot (eq. 28), padded with
      zeros to ``n_spots`` (capped at 10⁶);
    * ``belief`` (when ``belief_bins > 0``): the heading belief summed into
      ``belief_bins`` equal sectors starting at 0°.

    Where the env has no atlas yet (the learning phase of
    ``vc_gym/LearnThenHome-v0`` with ``learning="agent"``) the added keys are zeros,
    the heading spread is 180°, the position spread 100 m and the belief uniform.

    ``info["estimate"]`` holds the tracker's state as plain numbers (``heading_deg``,
    ``heading_spread_deg``, ``position``, ``position_std_m``), or ``None`` without an
    atlas, for recording and plotting; ``last_state`` is the full
    :class:`~vc_gym.localization.TrackerState`.

    Parameters
    ----------
    env : gymnasium.Env
        An env whose observations hold ``image``, ``head`` and ``odometry`` like
        ``vc_gym/AiboRoom-v0`` (its ``unwrapped`` must have ``control_dt`` and a
        ``camera`` with ``hfov_deg``).
    atlas : CompassAtlas, optional
        The learned atlas. Default: ``env.unwrapped.atlas``, read again at every
        reset (``vc_gym/LearnThenHome-v0`` learns it during reset).
    n_spots : int, optional
        Length of ``goodness``. Default: the atlas' spot count, or
        ``env.unwrapped.max_spots``.
    keep_image : bool
        Keep the camera frame in the observation. Learned agents usually drop it and
        work from the compass outputs alone (a small MLP policy, fast training).
    belief_bins : int
        Number of sectors of the downsampled heading belief (0: no ``belief`` key).
        Must divide 360.
    tracker : str, dict, callable or Tracker
        Which tracker: ``"grid"`` (default), ``"particle"``, ``"kalman"``, a dict
        ``{"type": name, **kwargs}``, a callable returning a tracker, or a tracker
        (see :func:`vc_gym.localization.make_tracker`). It is built once and reset at
        every episode with the atlas, the head camera and the env's ``control_dt``.
    """

    def __init__(
        self,
        env: gym.Env,
        atlas: CompassAtlas | None = None,
        n_spots: int | None = None,
        keep_image: bool = True,
        belief_bins: int = 0,
        tracker: TrackerSpec = "grid",
    ):
        gym.utils.RecordConstructorArgs.__init__(
            self,
            atlas=atlas,
            n_spots=n_spots,
            keep_image=keep_image,
            belief_bins=belief_bins,
            tracker=tracker,
        )
        gym.Wrapper.__init__(self, env)
        inner = env.observation_space
        if not isinstance(inner, spaces.Dict) or not {"image", "head", "odometry"} <= set(
            inner.spaces
        ):
            raise ValueError(
                "CompassObservation needs a Dict observation with 'image', 'head' and "
                f"'odometry' (like vc_gym/AiboRoom-v0), got {inner}"
            )
        if atlas is not None and not isinstance(atlas, CompassAtlas):
            raise ValueError(f"atlas must be a CompassAtlas, got {type(atlas).__name__}")
        if atlas is None and not hasattr(env.unwrapped, "atlas"):
            raise ValueError(
                "pass an atlas: the wrapped env does not learn one (only "
                "vc_gym/LearnThenHome-v0 does)"
            )
        if n_spots is None:
            n_spots = len(atlas) if atlas is not None else getattr(env.unwrapped, "max_spots", 0)
        if int(n_spots) < 1:
            raise ValueError(f"n_spots must be >= 1, got {n_spots!r}")
        belief_bins = int(belief_bins)
        if belief_bins < 0 or (belief_bins and 360 % belief_bins):
            raise ValueError(f"belief_bins must be 0 or divide 360, got {belief_bins}")
        self.fixed_atlas = atlas
        self.n_spots = int(n_spots)
        self.keep_image = bool(keep_image)
        self.belief_bins = belief_bins
        self.camera = Camera(hfov_deg=env.unwrapped.camera.hfov_deg)
        self.tracker: Tracker = make_tracker(tracker)
        self._attached = False
        self.last_state: TrackerState | None = None
        #: wall time spent in ``tracker.update`` and the number of updates (a benchmark
        #: figure; nothing the agent sees depends on it)
        self.tracker_time_s = 0.0
        self.tracker_updates = 0

        keys = dict(inner.spaces)
        if not self.keep_image:
            del keys["image"]
        keys["heading"] = spaces.Box(-1.0, 1.0, (2,), np.float32)
        keys["heading_spread"] = spaces.Box(0.0, 180.0, (1,), np.float32)
        keys["position"] = spaces.Box(-100.0, 100.0, (2,), np.float32)
        keys["position_std"] = spaces.Box(0.0, 100.0, (2,), np.float32)
        keys["home_vector"] = spaces.Box(-200.0, 200.0, (2,), np.float32)
        keys["goodness"] = spaces.Box(0.0, _BIG, (self.n_spots,), np.float32)
        if self.belief_bins:
            keys["belief"] = spaces.Box(0.0, 1.0, (self.belief_bins,), np.float32)
        self.observation_space = spaces.Dict(keys)

    @property
    def atlas(self) -> CompassAtlas | None:
        """The atlas in use (``None`` before the env has learned one)."""
        if self.fixed_atlas is not None:
            return self.fixed_atlas
        return getattr(self.env.unwrapped, "atlas", None)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        self._attached = False
        self._attach()
        return self._augment(obs, info), info

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if not self._attached:
            self._attach()  # the atlas may have been learned during this step
        return self._augment(obs, info), reward, terminated, truncated, info

    def _attach(self) -> None:
        atlas = self.atlas
        if atlas is None:
            return
        if len(atlas) > self.n_spots:
            raise ValueError(
                f"the atlas has {len(atlas)} spots but the observation holds {self.n_spots}"
            )
        self.tracker.reset(atlas, self.camera, self.env.unwrapped.control_dt)
        self._attached = True

    def _augment(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> dict[str, np.ndarray]:
        out = {k: v for k, v in obs.items() if self.keep_image or k != "image"}
        goodness = np.zeros(self.n_spots, np.float32)
        if not self._attached:
            self.last_state = None
            heading = np.zeros(2, np.float32)
            spread, position, home_vec = 180.0, np.zeros(2), np.zeros(2)
            position_std = np.full(2, 100.0)
            belief_sectors = np.full(self.belief_bins, 1.0 / max(self.belief_bins, 1))
            info["estimate"] = None
        else:
            t0 = time.perf_counter()
            state = self.tracker.update(
                obs["image"], float(obs["head"][0]), np.asarray(obs["odometry"], np.float64)
            )
            self.tracker_time_s += time.perf_counter() - t0
            self.tracker_updates += 1
            if not isinstance(state, TrackerState):
                raise TypeError(
                    f"{type(self.tracker).__name__}.update must return a TrackerState, "
                    f"got {type(state).__name__}"
                )
            self.last_state = state
            th = math.radians(state.heading_deg)
            heading = np.array([math.cos(th), math.sin(th)], np.float32)
            spread = state.heading_spread_deg
            position = np.asarray(state.position, np.float64)
            position_std = np.asarray(state.position_std_m, np.float64)
            hx, hy = np.asarray(self.atlas.home_position) - position
            home_vec = np.array(world_to_body(hx, hy, state.heading_deg))
            g = np.minimum(state.goodness, _BIG)
            goodness[: g.size] = g
            belief_sectors = state.belief_sectors(self.belief_bins) if self.belief_bins else None
            info["estimate"] = {
                "heading_deg": float(state.heading_deg),
                "heading_spread_deg": float(spread),
                "position": [float(position[0]), float(position[1])],
                "position_std_m": [float(position_std[0]), float(position_std[1])],
            }
        out["heading"] = heading
        out["heading_spread"] = np.array([min(spread, 180.0)], np.float32)
        out["position"] = np.clip(position, -100.0, 100.0).astype(np.float32)
        out["position_std"] = np.clip(position_std, 0.0, 100.0).astype(np.float32)
        out["home_vector"] = np.clip(home_vec, -200.0, 200.0).astype(np.float32)
        out["goodness"] = goodness
        if self.belief_bins:
            out["belief"] = np.asarray(belief_sectors, np.float32)
        return out
