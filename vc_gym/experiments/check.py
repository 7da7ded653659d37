"""``vc-gym check``: the end-to-end self-test a user runs on their own machine.

Each case does what a hostile file, a careless user or a crashing process would do,
through the loaders, the registered envs, the job runner and the ``vc-gym`` commands, and
checks that vc_gym answers with a clear error of the promised kind:

- hostile files: map, model and settings files that are bombs, pickled payloads, bit
  flipped or deeply nested (:class:`~vc_gym.errors.MapFileError`, ``ValueError`` or
  :class:`~vc_gym.training.safe_load.UnsafeModelError`; nothing decompressed in full,
  no code from the file run);
- envs: the same misuse of every registered ``vc_gym/`` env (bad actions, a step before
  reset, bad reset options and seeds, use after close; a new env is covered without a
  new case) and the same first observation for the same seed;
- faults: a worker killed once (its job retried) or every time (its job reported
  failed) within seconds, a finished run rerun (nothing redone), a lost physics server
  (a ``RuntimeError``; ``reset()`` rebuilds the world);
- the security suites of :mod:`vc_gym.experiments.check_security`: files that name
  code, bombs, runs that would destroy runs, command arguments refused before work;
- the footage suite of :mod:`vc_gym.experiments.check_footage`: ``vc-gym compass
  learn/track`` never replacing an input or an earlier output, the pixel limit after
  scaling, truncated frames, SIGTERM, errors that name the flag typed, and the envs'
  time limits.

A case fails if anything else happens: another exception, no exception, a hang (each
case has a time limit), or code from a file running. A short
:func:`~vc_gym.experiments.benchmarks.soak.soak` then reports speed and memory figures.
The argument checks of single functions (compass, filters, trackers, heading sensors)
are unit tests under ``tests/``, not cases here.
"""

from __future__ import annotations

import base64
import functools
import io
import os
import pickle
import tempfile
import time
import traceback
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import vc_gym  # noqa: F401  (registers the envs)
from vc_gym.compass import Camera, CompassConfig, VisualCompass
from vc_gym.config_files import read_settings
from vc_gym.errors import MapFileError
from vc_gym.experiments.benchmarks.soak import soak
from vc_gym.experiments.check_case import Case, raises
from vc_gym.experiments.check_footage import footage_cases
from vc_gym.experiments.check_security import model_with_data, security_cases
from vc_gym.jobs.backends import LocalBackend
from vc_gym.jobs.job import Job
from vc_gym.jobs.run import ExperimentRun
from vc_gym.persistence import load_npz_checked, save_npz_atomic
from vc_gym.training.safe_load import UnsafeModelError, load_sb3_model
from vc_gym.worlds.panorama import render_view
from vc_gym.worlds.panorama_painters import make_panorama

__all__ = ["Case", "all_cases", "run_check"]

#: A case taking longer than this (seconds) fails as a hang.
CASE_TIME_LIMIT_S = 60.0


# --------------------------------------------------------------------------- hostile files
@functools.cache
def _panorama() -> np.ndarray:
    """The synthetic room panorama the hostile maps are learned on (made once)."""
    return make_panorama(np.random.default_rng(7), width=1200, height=300, kind="room")


@functools.cache
def _learned() -> VisualCompass:
    """A compass learned on the synthetic room panorama (built once per process)."""
    pano = _panorama()
    vc = VisualCompass()
    vc.fit_colors([render_view(pano, Camera(yaw_deg=a)) for a in range(0, 360, 45)])
    for a in range(0, 360, 15):
        vc.learn(render_view(pano, Camera(yaw_deg=a)), Camera(yaw_deg=a))
    return vc


def _npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, array, allow_pickle=True)
    return buf.getvalue()


def _base_entries() -> dict[str, bytes]:
    return {
        "schema.npy": _npy(np.array("vc_gym.Check")),
        "schema_version.npy": _npy(np.array(1, np.int64)),
    }


def _write_zip(path: Path, entries: dict[str, bytes]) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in entries.items():
            zf.writestr(name, data)
    return path


def _refused(path: Path) -> None:
    raises(MapFileError, path.name, lambda: load_npz_checked(path, "vc_gym.Check", 1))


def _zip_bomb(tmp: Path) -> None:
    path = tmp / "bomb.npz"
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": (2**25,)}
    )
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in _base_entries().items():
            zf.writestr(name, data)
        with zf.open("extra.npy", "w", force_zip64=True) as fh:
            fh.write(header.getvalue())
            for _ in range(16):
                fh.write(bytes(2**24))  # 256 MiB of zeros: ~250 KB compressed
    t0 = time.perf_counter()
    _refused(path)
    assert time.perf_counter() - t0 < 5.0, "the bomb was decompressed"


def _huge_shape(tmp: Path) -> None:
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)}
    )
    _refused(_write_zip(tmp / "shape.npz", {**_base_entries(), "a.npy": header.getvalue()}))


def _object_array(tmp: Path) -> None:
    entries = {**_base_entries(), "a.npy": _npy(np.array([{"x": 1}], dtype=object))}
    _refused(_write_zip(tmp / "objects.npz", entries))


def _load_bit_flipped(good: Path, flips: int, load: Callable[[Path], object], tmp: Path) -> None:
    """Flip one byte at ``flips`` places of the file ``good`` in turn and ``load`` each
    copy: only :class:`MapFileError` may come out (anything else fails the case)."""
    data = good.read_bytes()
    for i in range(0, len(data), max(1, len(data) // flips)):
        flipped = bytearray(data)
        flipped[i] ^= 0xFF
        path = tmp / "flipped.npz"
        path.write_bytes(bytes(flipped))
        try:
            load(path)
        except MapFileError:
            pass


def _bit_flips(tmp: Path) -> None:
    good = save_npz_atomic(tmp / "good.npz", "vc_gym.Check", 1, {"a": np.arange(50.0)})
    _load_bit_flipped(good, 40, lambda p: load_npz_checked(p, "vc_gym.Check", 1), tmp)


def _map_light_tampered(tmp: Path) -> None:
    """A map learned with ``exposure="map"`` whose light map is missing, negative or
    brighter than white is refused; bit flips in it give only :class:`MapFileError`."""
    pano = _panorama()
    vc = VisualCompass(CompassConfig(exposure="map", n_colors=4))
    vc.fit_colors([render_view(pano, Camera(yaw_deg=a)) for a in range(0, 360, 90)])
    for a in range(0, 360, 45):
        vc.learn(render_view(pano, Camera(yaw_deg=a)), Camera(yaw_deg=a))
    good = vc.save(tmp / "light.npz")
    arrays = dict(np.load(good, allow_pickle=False))
    for change, why in (
        ({"light_sum": None}, "light_sum"),
        ({"light_sum": -arrays["light_sum"]}, ">= 0"),
        ({"light_sum": 2.0 * arrays["light_columns"]}, "exceeds"),
    ):
        bad = {k: v for k, v in {**arrays, **change}.items() if v is not None}
        np.savez(tmp / "bad_light.npz", **bad)
        raises(MapFileError, why, lambda: VisualCompass.load(tmp / "bad_light.npz"))
    _load_bit_flipped(good, 40, VisualCompass.load, tmp)


def _renamed_npy(tmp: Path) -> None:
    np.save(tmp / "x.npy", np.zeros(3))
    (tmp / "x.npy").rename(tmp / "renamed.npz")
    _refused(tmp / "renamed.npz")


def _text_version(tmp: Path) -> None:
    entries = {**_base_entries(), "schema_version.npy": _npy(np.array("1"))}
    _refused(_write_zip(tmp / "version.npz", entries))


def _deep_map_config(tmp: Path) -> None:
    arrays = dict(_learned().to_arrays())
    arrays["config"] = np.array("[" * 50_000 + "]" * 50_000)
    path = save_npz_atomic(tmp / "deep.npz", "vc_gym.VisualCompass", 1, arrays)
    raises(MapFileError, "deep.npz", lambda: VisualCompass.load(path))


class _Payload:
    """Unpickling this creates a file: proof that code from a model file ran."""

    def __init__(self, marker: str):
        self.marker = marker

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _hostile_model(tmp: Path) -> None:

    marker = tmp / "code-ran"
    payload = base64.b64encode(pickle.dumps(_Payload(str(marker)))).decode()

    def plant(data: dict[str, Any]) -> None:
        data["lr_schedule"][":serialized:"] = payload
        data["extra_object"] = {":type:": "<class 'x'>", ":serialized:": payload}

    path = model_with_data(tmp, plant)
    raises(UnsafeModelError, "", lambda: load_sb3_model("ppo", path))
    assert not marker.exists(), "code from the model file ran"


def _settings_file(text: str, name: str) -> Callable[[Path], None]:
    def run(tmp: Path) -> None:

        path = tmp / name
        path.write_text(text)
        raises(ValueError, name, lambda: read_settings(path))

    return run


def _hostile_file_cases() -> list[Case]:
    return [
        Case("hostile_file", "npz: 256 MiB zero entry (zip bomb)", _zip_bomb),
        Case("hostile_file", "npz: header declares 1e6 x 1e6", _huge_shape),
        Case("hostile_file", "npz: pickled object array", _object_array),
        Case("hostile_file", "npz: bit flips", _bit_flips),
        Case("hostile_file", "npz: a renamed .npy", _renamed_npy),
        Case("hostile_file", "map: exposure='map' light map tampered", _map_light_tampered),
        Case("hostile_file", "npz: schema_version '1'", _text_version),
        Case("hostile_file", "map: deeply nested config JSON", _deep_map_config),
        Case("hostile_file", "model.zip: pickled payload", _hostile_model),
        Case(
            "hostile_file",
            "settings: YAML python tag",
            _settings_file("algo: !!python/object/apply:os.system ['true']\n", "tag.yml"),
        ),
        Case(
            "hostile_file",
            "settings: nested 100,000 deep",
            _settings_file("[" * 100_000 + "]" * 100_000, "deep.json"),
        ),
        Case(
            "hostile_file",
            "settings: 2 MB file",
            _settings_file('{"algo": "' + "x" * 2_000_000 + '"}', "big.json"),
        ),
    ]


# --------------------------------------------------------------------------- faults
def die_once(marker: str) -> dict[str, Any]:
    """Job: the worker process dies the first time (as if OOM-killed), succeeds after."""
    path = Path(marker)
    if not path.exists():
        path.write_text("died once")
        os._exit(9)
    return {"ok": True}


def die_always() -> dict[str, Any]:
    """Job: the worker process always dies."""
    os._exit(9)


def _runner(tmp: Path, jobs: list, name: str) -> tuple[list, Any]:

    with LocalBackend(workers=2) as backend:
        run = ExperimentRun(tmp / name, "check", backend, {"check": name}, progress=False)
        out = run.run("jobs", jobs)
        return out, run


def _dead_worker_retried(tmp: Path) -> None:

    jobs = [Job("a", f"{__name__}:die_once", {"marker": str(tmp / "died")})]
    t0 = time.perf_counter()
    out, _ = _runner(tmp, jobs, "retry")
    assert out == [{"ok": True}], f"a job whose worker died once was not retried: {out}"
    assert time.perf_counter() - t0 < 30.0


def _dead_worker_reported(tmp: Path) -> None:

    t0 = time.perf_counter()
    out, run = _runner(tmp, [Job("a", f"{__name__}:die_always", {})], "dead")
    assert out == [None] and run.failures, "a job whose worker always dies must be reported"
    assert time.perf_counter() - t0 < 30.0


def _resumed_run(tmp: Path) -> None:

    jobs = [Job(f"j{i}", "vc_gym.experiments.check:square", {"x": i}) for i in range(3)]
    first, _ = _runner(tmp, jobs, "resume")
    second, run = _runner(tmp, jobs, "resume")
    assert first == second and run.stages["jobs"]["ran"] == 0, "a finished run ran again"


def square(x: float) -> dict[str, Any]:
    """Job: a figure of ``x``."""
    return {"x": x, "square": x * x}


def _lost_client(_: Path) -> None:
    env = gym.make("vc_gym/AiboRoom-v0")
    try:
        first, _ = env.reset(seed=3)
        env.unwrapped.client.disconnect()
        raises(RuntimeError, "physics server", lambda: env.step(np.zeros(5, np.float32)))
        again, _ = env.reset(seed=3)
        assert np.array_equal(first["image"], again["image"]), "reset did not rebuild the world"
    finally:
        env.close()


def _fault_cases() -> list[Case]:
    return [
        Case("fault", "worker killed once: job retried", _dead_worker_retried),
        Case("fault", "worker always killed: job reported failed", _dead_worker_reported),
        Case("fault", "finished run rerun: nothing redone", _resumed_run),
        Case("fault", "physics server lost: clear error, reset rebuilds", _lost_client),
    ]


# --------------------------------------------------------------------------- every env
#: Small settings for the registered envs whose first reset runs a learning phase.
_ENV_KWARGS: dict[str, dict[str, Any]] = {
    "vc_gym/LearnThenHome-v0": {"learn_time_s": 0.2},
    "vc_gym/Homing-v0": {"learn_time_s": 0.2},
}


class _SharedEnv:
    """One env of a registered id for all of its cases (made on first use): its first
    case steps it before any reset, its last one closes it."""

    def __init__(self, env_id: str):
        self.env_id = env_id
        self._env: gym.Env | None = None

    def get(self) -> gym.Env:
        if self._env is None:
            self._env = gym.make(self.env_id, **_ENV_KWARGS.get(self.env_id, {}))
        return self._env

    def reset(self) -> gym.Env:
        env = self.get()
        env.reset(seed=0)
        return env

    def close(self) -> gym.Env:
        env = self.get()
        env.close()
        return env


def _same_observation(a: Any, b: Any) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)
    return bool(np.array_equal(a, b))


def _same_seed_same_start(shared: _SharedEnv) -> None:
    env = shared.get()
    first, _ = env.reset(seed=3)
    again, _ = env.reset(seed=3)
    assert _same_observation(first, again), "two resets with seed 3 differ"


def _after_close(shared: _SharedEnv) -> None:
    env = shared.close()
    n = env.action_space.shape[0]
    raises(RuntimeError, "closed", lambda: env.step(np.zeros(n, np.float32)))
    raises(RuntimeError, "closed", lambda: env.reset(seed=0))
    raises(RuntimeError, "closed", env.render)


def _bad_actions(n: int) -> dict[str, Any]:
    """Actions every env must refuse with a ValueError (``n``: its action length)."""
    return {
        "NaN action": np.full(n, np.nan, np.float32),
        "infinite action": np.full(n, np.inf, np.float32),
        "action too short": np.zeros(n - 1, np.float32),
        "action too long": np.zeros(n + 1, np.float32),
        "2-D action": np.zeros((1, n), np.float32),
        "text action": "forward",
        "None action": None,
    }


def _step_before_reset(shared: _SharedEnv) -> None:
    env = shared.get()
    action = np.zeros(env.action_space.shape, np.float32)
    raises(gym.error.ResetNeeded, "reset", lambda: env.step(action))


def _bad_action(shared: _SharedEnv, name: str) -> None:
    env = shared.reset()
    action = _bad_actions(int(env.action_space.shape[0]))[name]
    raises(ValueError, "", lambda: env.step(action))


def _env_cases() -> list[Case]:
    """The same misuse of every registered ``vc_gym/`` env (Minigrid-style: a new env
    is covered without a new case)."""
    cases = []
    for env_id in sorted(k for k in gym.registry if k.startswith("vc_gym/")):
        shared = _SharedEnv(env_id)

        def case(name: str, fn: Callable[[], None], env_id: str = env_id) -> Case:
            return Case("envs", f"{env_id}: {name}", lambda _, fn=fn: fn())

        cases.append(case("step before reset", lambda s=shared: _step_before_reset(s)))
        for name in _bad_actions(1):
            cases.append(case(name, lambda s=shared, name=name: _bad_action(s, name)))
        resets = {
            "unknown reset option": {"options": {"nope": 1}},
            "NaN reset pose": {"options": {"pose": (np.nan, 0.0, 0.0)}},
            "negative seed": {"seed": -1},
        }
        for name, kwargs in resets.items():
            cases.append(
                case(
                    name,
                    lambda s=shared, kw=kwargs: raises(
                        (ValueError, gym.error.Error), "", lambda: s.get().reset(**kw)
                    ),
                )
            )
        cases.append(
            case("same seed, same first observation", lambda s=shared: _same_seed_same_start(s))
        )
        cases.append(case("step, reset and render after close", lambda s=shared: _after_close(s)))
    return cases


def all_cases(main: Callable[[list[str]], int] | None = None) -> list[Case]:
    """Every case of every suite (built on demand: some import heavy modules).

    ``main`` (:func:`vc_gym.cli.main`, passed in by the command: this layer does not
    import the command line) runs the footage suite's commands in this process; without
    it each runs in a process of its own.
    """
    return [
        *_hostile_file_cases(),
        *_env_cases(),
        *_fault_cases(),
        *security_cases(),
        *footage_cases(main),
    ]


def run_check(
    soak_steps: int = 2_000,
    soak_cycles: int = 30,
    progress: bool = True,
    cases: list[Case] | None = None,
) -> dict[str, Any]:
    """Run every case (or ``cases``) and a short soak; return the counts, the failures
    and the soak's figures.

    Returns
    -------
    dict
        ``tried``, ``passed``, ``failed``, ``failures`` (suite, case, error),
        ``suites`` (tried/passed per suite) and ``soak`` (the soak's figures).
    """

    cases = all_cases() if cases is None else list(cases)
    failures, suites = [], {}
    with tempfile.TemporaryDirectory(prefix="vc_gym_check_") as tmp:
        for k, case in enumerate(tqdm(cases, desc="check", disable=not progress)):
            folder = Path(tmp) / f"case{k}"
            folder.mkdir()
            s = suites.setdefault(case.suite, {"tried": 0, "passed": 0})
            s["tried"] += 1
            t0 = time.perf_counter()
            try:
                case.run(folder)
                took = time.perf_counter() - t0
                if took > CASE_TIME_LIMIT_S:
                    raise AssertionError(f"took {took:.0f} s (limit {CASE_TIME_LIMIT_S:.0f} s)")
            except Exception as exc:  # noqa: BLE001 - every escape is a failed case
                failures.append(
                    {
                        "suite": case.suite,
                        "case": case.name,
                        "error": f"{type(exc).__name__}: {exc}"[:500],
                        "where": traceback.format_exc(limit=-2)[-600:],
                    }
                )
                continue
            s["passed"] += 1
    window = max(10, soak_steps // 4)
    figures = soak(soak_steps, soak_cycles, window, progress=progress)
    return {
        "tried": len(cases),
        "passed": len(cases) - len(failures),
        "failed": len(failures),
        "failures": failures,
        "suites": suites,
        "soak": figures,
    }
