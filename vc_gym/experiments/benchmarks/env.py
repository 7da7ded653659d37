"""Speed of the simulated room: the env against bare PyBullet, and vector envs.

``steps_per_s`` is one ``vc_gym/AiboRoom-v0`` stepping with random actions at the
default settings (208×160 camera, default locomotion). ``bare_steps_per_s`` is what
PyBullet itself costs for the same work with no env around it: the same number of
physics substeps and one ``getCameraImage`` of the same scene from the robot's eye.
Both are measured in alternating rounds in one run and reported as medians.
``async2_speedup`` compares a 2-env ``AsyncVectorEnv`` (env-steps per second) with one
env, measured in the same run.
"""

from __future__ import annotations

import time

import gymnasium as gym
import numpy as np

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.sim.bullet import connect, pybullet
from vc_gym.sim.head_camera import HeadCameraSpec
from vc_gym.sim.robot import Quadruped
from vc_gym.sim.scenes import build_scene, check_scene_name
from vc_gym.validation import check_seed, flag, int_in_range

__all__ = ["bench_env"]

ENV_ID = "vc_gym/AiboRoom-v0"
#: Most steps per timed round.
MAX_STEPS = 100_000
#: Most timed rounds.
MAX_ROUNDS = 1_000


def _env_rate(env: gym.Env, actions: np.ndarray) -> float:
    t0 = time.perf_counter()
    for a in actions:
        _, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            env.reset()
    return len(actions) / (time.perf_counter() - t0)


class _Bare:
    """The same scene, robot and camera, driven by raw PyBullet calls only."""

    def __init__(self, scene: str, control_dt: float, spec: HeadCameraSpec, seed: int):
        self.bc = connect(pybullet.DIRECT)
        build_scene(self.bc, scene, rng=np.random.default_rng(seed))
        robot = Quadruped(self.bc, "constraint", rng=np.random.default_rng(seed))
        robot.reset(0.0, 0.0, 30.0)
        robot.set_visible(False)  # the env hides the robot from its head camera too
        self.substeps = int(round(control_dt * robot.physics_hz))
        self.spec = spec
        eye, yaw, pitch = robot.eye()
        y, p = np.radians(yaw), np.radians(pitch)
        target = np.array(eye) + [np.cos(p) * np.cos(y), np.cos(p) * np.sin(y), np.sin(p)]
        self.view = self.bc.computeViewMatrix(eye, target.tolist(), [0, 0, 1])
        self.proj = spec.projection(self.bc)

    def rate(self, steps: int) -> float:
        bc = self.bc
        t0 = time.perf_counter()
        for _ in range(steps):
            for _ in range(self.substeps):
                bc.stepSimulation()
            bc.getCameraImage(
                self.spec.width,
                self.spec.height,
                self.view,
                self.proj,
                renderer=bc.ER_TINY_RENDERER,
                shadow=0,
                flags=bc.ER_NO_SEGMENTATION_MASK,
            )
        return steps / (time.perf_counter() - t0)

    def close(self) -> None:
        self.bc.disconnect()


def bench_env(
    steps: int = 60, rounds: int = 5, seed: int = 0, scene: str = "robolab", vector: bool = True
) -> dict[str, object]:
    """Measure env, bare-PyBullet and vector-env stepping rates side by side.

    Parameters
    ----------
    steps : int
        Steps per timed round (1 to :data:`MAX_STEPS`).
    rounds : int
        Alternating env / bare rounds (medians are reported; 1 to :data:`MAX_ROUNDS`).
    seed : int
        Seed of actions and env.
    scene : str
        Registered scene to benchmark (:func:`vc_gym.sim.scenes.scene_names`). The
        async vector env builds it in worker processes: a scene registered in your own
        code must be registered there too (see :mod:`vc_gym.sim.scenes`).
    vector : bool
        Also measure 2-env sync and async vector envs.
    """
    int_in_range("steps", steps, 1, MAX_STEPS)
    int_in_range("rounds", rounds, 1, MAX_ROUNDS)
    check_seed("seed", seed)
    flag("vector", vector)
    check_scene_name(scene)
    rng = np.random.default_rng(seed)
    env = gym.make(ENV_ID, scene=scene)
    env.reset(seed=seed)
    spec = env.unwrapped.camera
    control_dt = env.unwrapped.control_dt
    bare = _Bare(scene, control_dt, spec, seed)
    actions = rng.uniform(-1, 1, (steps, 5)).astype(np.float32)
    _env_rate(env, actions[:5])  # warm up caches
    bare.rate(5)
    env_rates, bare_rates = [], []
    for _ in range(rounds):
        env_rates.append(_env_rate(env, actions))
        bare_rates.append(bare.rate(steps))
    env.close()
    bare.close()
    steps_per_s = float(np.median(env_rates))
    bare_steps_per_s = float(np.median(bare_rates))
    result: dict[str, object] = {
        "benchmark": "env",
        "env_id": ENV_ID,
        "scene": scene,
        "frame": f"{spec.width}x{spec.height}",
        "control_dt_s": control_dt,
        "physics_substeps": bare.substeps,
        "steps_per_s": steps_per_s,
        "bare_steps_per_s": bare_steps_per_s,
        "env_over_bare": steps_per_s / bare_steps_per_s,
        "realtime_factor": steps_per_s * control_dt,
        "steps": steps,
        "rounds": rounds,
    }
    if vector:
        for mode in ("sync", "async"):
            venv = gym.make_vec(ENV_ID, num_envs=2, vectorization_mode=mode, scene=scene)
            venv.reset(seed=seed)
            vactions = rng.uniform(-1, 1, (steps, 2, 5)).astype(np.float32)
            for a in vactions[:5]:
                venv.step(a)
            rates = []
            for _ in range(max(1, rounds // 2)):
                t0 = time.perf_counter()
                for a in vactions:
                    venv.step(a)
                rates.append(2 * steps / (time.perf_counter() - t0))
            venv.close()
            result[f"{mode}2_env_steps_per_s"] = float(np.median(rates))
            result[f"{mode}2_speedup"] = float(np.median(rates)) / steps_per_s
    return result
