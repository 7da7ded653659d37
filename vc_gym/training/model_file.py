"""A trained policy saved so that the same training gives the same bytes.

stable-baselines3's ``model.save`` writes, besides the weights, things that change from
one run to the next although the policy does not: the zip entries' dates, the wall-clock
start of training (``start_time``), the last episodes' wall times (``ep_info_buffer``),
memory addresses in the descriptions of pickled classes and the machine's kernel in
``system_info.txt``. :func:`save_reproducible_model` writes the model without them, so
that ``vc-gym train`` with the same settings and seed writes the same ``model.zip``
(the shipped policy is checked this way). What it drops, no loader needs:
stable-baselines3 rebuilds the episode buffers and the start time when training goes
on, and reads only ``:serialized:`` of a pickled entry (the descriptions beside it that
print an object's address are dropped; :mod:`vc_gym.training.safe_load` reads the
others, such as a space's shape).
"""

from __future__ import annotations

import io
import json
import os
import re
import zipfile
from pathlib import Path
from typing import Any

from vc_gym.persistence import write_atomic

__all__ = ["reproducible_model_bytes", "save_reproducible_model"]

#: ``data`` fields that record the run's wall clock, not the policy.
_WALL_CLOCK_FIELDS = ("start_time", "ep_info_buffer", "ep_success_buffer")
#: The keys of a pickled entry's description that stable-baselines3's loading reads.
_SERIALIZED_KEYS = (":type:", ":serialized:")
#: An object's address in a description (``<... object at 0x7f...>``).
_ADDRESS = re.compile(r" at 0x[0-9a-fA-F]+")
#: The date every zip entry gets (the earliest a zip can hold).
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)


def reproducible_model_bytes(saved: bytes) -> bytes:
    """``saved`` (a stable-baselines3 model zip) without what changes between runs.

    Raises
    ------
    ValueError
        If ``saved`` is not a model zip with a JSON ``data`` entry.
    """
    try:
        with zipfile.ZipFile(io.BytesIO(saved)) as zin:
            entries = {info.filename: zin.read(info) for info in zin.infolist()}
        data = json.loads(entries["data"])
    except (zipfile.BadZipFile, KeyError, ValueError) as exc:
        raise ValueError(f"not a stable-baselines3 model zip: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError("not a stable-baselines3 model zip: 'data' is not a JSON object")
    entries["data"] = json.dumps(_plain_data(data), indent=4, sort_keys=True).encode()
    if "system_info.txt" in entries:
        lines = entries["system_info.txt"].decode("utf-8", "replace").splitlines()
        kept = [line for line in lines if not line.startswith("- OS:")]
        entries["system_info.txt"] = ("\n".join(kept) + "\n").encode()
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zout:
        for name, content in entries.items():
            info = zipfile.ZipInfo(name, date_time=_ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zout.writestr(info, content)
    return out.getvalue()


def _plain_data(data: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key in _WALL_CLOCK_FIELDS:
            continue
        if isinstance(value, dict) and ":serialized:" in value:
            # descriptions that print an object's address change from run to run
            value = {
                k: v
                for k, v in value.items()
                if not (isinstance(v, str) and _ADDRESS.search(v)) or k in _SERIALIZED_KEYS
            }
        out[key] = value
    return out


def save_reproducible_model(model: Any, path: str | os.PathLike) -> Path:
    """Save the stable-baselines3 ``model`` to ``path`` atomically, without what changes
    between runs (:func:`reproducible_model_bytes`)."""
    buffer = io.BytesIO()
    model.save(buffer)
    content = reproducible_model_bytes(buffer.getvalue())
    return write_atomic(path, lambda tmp: Path(tmp).write_bytes(content))
