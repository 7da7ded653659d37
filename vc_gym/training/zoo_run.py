"""What an RL Baselines3 Zoo run saved beside its model, read as plain data.

``python -m rl_zoo3.train --algo ppo --env vc_gym/Homing-v0 -f logs ...`` writes
``logs/ppo/vc_gym-Homing-v0_1/vc_gym-Homing-v0.zip`` (the model; checkpoints and
``best_model.zip`` lie beside it) and, in the folder ``vc_gym-Homing-v0/`` beside it,
``config.yml`` (the hyperparameters it trained with, ``env_kwargs`` included) and
``args.yml`` (its command line: ``algo``, ``env``, ...). Both are YAML dumps of Python
``OrderedDict`` objects (``!!python/object/apply:collections.OrderedDict``), which
PyYAML's own loaders either refuse (safe) or build by calling the named function
(unsafe). :func:`read_zoo_file` reads them with a safe loader that turns that one tag
into a plain dict of its pairs and refuses every other Python tag, aliases and repeated
keys, within a size limit.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from vc_gym.config_files import _yaml_loader
from vc_gym.plugins import check_plain_data

__all__ = [
    "MAX_ZOO_FILE_BYTES",
    "ZOO_ENV_ID",
    "ZooRun",
    "find_zoo_run",
    "read_zoo_file",
]

#: The env a Zoo run must have trained on for vc_gym to evaluate it.
ZOO_ENV_ID = "vc_gym/Homing-v0"
#: Largest ``config.yml`` / ``args.yml`` read (a Zoo run's are about 2 kB).
MAX_ZOO_FILE_BYTES = 1_000_000
_ORDERED_DICT = "tag:yaml.org,2002:python/object/apply:collections.OrderedDict"
_TUPLE = "tag:yaml.org,2002:python/tuple"
#: Zoo hyperparameters that change what the model observes, which an evaluation
#: outside the Zoo does not reproduce.
_WRAPPING = ("normalize", "frame_stack", "env_wrapper", "vec_env_wrapper")


def _zoo_loader():
    import yaml

    class Loader(_yaml_loader()):
        pass

    def ordered_dict(loader: Loader, node: Any) -> dict[Any, Any]:
        args = loader.construct_sequence(node, deep=True)
        pairs = args[0] if len(args) == 1 else None
        if not isinstance(pairs, list) or not all(
            isinstance(p, list) and len(p) == 2 and isinstance(p[0], str) for p in pairs
        ):
            raise yaml.constructor.ConstructorError(
                None, None, "an OrderedDict must hold [key, value] pairs", node.start_mark
            )
        out: dict[str, Any] = {}
        for k, v in pairs:
            if k in out:
                raise yaml.constructor.ConstructorError(
                    None, None, f"key {k!r} appears twice", node.start_mark
                )
            out[k] = v
        return out

    def python_tuple(loader: Loader, node: Any) -> list[Any]:
        return loader.construct_sequence(node, deep=True)

    Loader.add_constructor(_ORDERED_DICT, ordered_dict)
    Loader.add_constructor(_TUPLE, python_tuple)
    return Loader


def read_zoo_file(path: str | os.PathLike) -> dict[str, Any]:
    """One of a Zoo run's ``config.yml`` / ``args.yml`` as a plain dict.

    Raises
    ------
    ValueError
        Naming the file: missing, larger than :data:`MAX_ZOO_FILE_BYTES`, not YAML,
        a Python tag other than ``OrderedDict``/``tuple`` (nothing is ever called or
        imported), an alias, a repeated key, or not a mapping of plain data.
    """
    import yaml

    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{p}: no such file")
    if p.stat().st_size > MAX_ZOO_FILE_BYTES:
        raise ValueError(f"{p}: larger than {MAX_ZOO_FILE_BYTES} bytes; not a Zoo run file")
    try:
        text = p.read_text(encoding="utf-8")
        data = yaml.load(text, Loader=_zoo_loader())  # noqa: S506 - a safe loader
    except Exception as exc:  # noqa: BLE001 - yaml.YAMLError, UnicodeDecodeError, ...
        raise ValueError(
            f"{p}: not a readable Zoo run file ({type(exc).__name__}: {exc})"
        ) from None
    if not isinstance(data, dict):
        raise ValueError(f"{p}: not a mapping")
    check_plain_data(data, str(p))
    return data


class ZooRun:
    """The saved settings of the Zoo run a model belongs to.

    Attributes
    ----------
    folder : Path
        The folder of ``config.yml`` and ``args.yml``.
    algo : str
        ``args.yml``'s ``algo``.
    env_id : str
        ``args.yml``'s ``env``.
    env_kwargs : dict
        The env arguments the run trained with (``config.yml``'s ``env_kwargs``).
    """

    def __init__(self, folder: Path):
        self.folder = folder
        config = read_zoo_file(folder / "config.yml")
        args = read_zoo_file(folder / "args.yml")
        self.algo = args.get("algo")
        self.env_id = args.get("env")
        if not isinstance(self.algo, str) or not isinstance(self.env_id, str):
            raise ValueError(f"{folder / 'args.yml'}: no 'algo' and 'env' names")
        kwargs = config.get("env_kwargs") or {}
        if not isinstance(kwargs, dict):
            raise ValueError(f"{folder / 'config.yml'}: 'env_kwargs' is not a mapping")
        self.env_kwargs: dict[str, Any] = dict(kwargs)
        wrapped = [k for k in _WRAPPING if config.get(k)]
        if wrapped:
            raise ValueError(
                f"{folder / 'config.yml'}: the run wrapped its envs ({', '.join(wrapped)}); "
                "an evaluation outside the Zoo would show the model other observations"
            )

    @property
    def config_path(self) -> Path:
        """The ``config.yml`` the env arguments came from."""
        return self.folder / "config.yml"


def find_zoo_run(model_path: str | os.PathLike) -> ZooRun | None:
    """The :class:`ZooRun` of a model saved by the Zoo, or ``None`` if the model has no
    Zoo run folder beside it (``RUN/<env name>/config.yml`` and ``args.yml``).

    Raises
    ------
    ValueError
        If the run folder's files cannot be read, or the run trained another env than
        :data:`ZOO_ENV_ID`.
    """
    run = Path(model_path).resolve().parent
    folders = sorted(
        d
        for d in run.iterdir()
        if d.is_dir() and (d / "config.yml").is_file() and (d / "args.yml").is_file()
    )
    if not folders:
        return None
    if len(folders) > 1:
        raise ValueError(f"{run}: several Zoo run folders ({[d.name for d in folders]})")
    zoo = ZooRun(folders[0])
    if zoo.env_id != ZOO_ENV_ID:
        raise ValueError(
            f"{zoo.folder / 'args.yml'}: the model was trained on {zoo.env_id!r}, "
            f"vc_gym evaluates {ZOO_ENV_ID} agents"
        )
    return zoo
