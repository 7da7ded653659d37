"""PyBullet without its banner: the modules, and client connections that print nothing.

PyBullet's C code prints its build time when imported and ``argv[0]=`` when a client
connects, straight to the process' stdout and stderr, where they mix with a command's
output and progress bars. Here the import and every connection run with both file
descriptors pointed at ``/dev/null`` (:func:`native_output_silenced`); everything else
PyBullet prints (warnings while loading a model, GUI messages) still shows.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator

__all__ = ["bullet_client", "connect", "native_output_silenced", "pybullet", "pybullet_data"]


def _flush_c_streams() -> None:
    """Flush the C library's stdio buffers (text printed by C code but not yet written)."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library to ask: nothing buffered we can reach
        pass


@contextlib.contextmanager
def native_output_silenced() -> Iterator[None]:
    """Send whatever C code writes to stdout and stderr during the block to ``/dev/null``.

    Works on the file descriptors (1 and 2), so it silences native libraries, not only
    Python's ``print``; Python's own streams are flushed first so nothing of theirs is
    lost, and the descriptors are restored however the block ends.
    """
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    _flush_c_streams()
    saved: list[tuple[int, int]] = []
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in (1, 2):
            try:
                saved.append((fd, os.dup(fd)))
            except OSError:  # that descriptor is closed: nothing to silence
                continue
            os.dup2(devnull, fd)
        yield
    finally:
        _flush_c_streams()
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)


with native_output_silenced():
    import pybullet
    import pybullet_data
    from pybullet_utils import bullet_client


def connect(mode: int | None = None) -> bullet_client.BulletClient:
    """A new PyBullet client (``pybullet.DIRECT`` unless ``mode`` says otherwise),
    connected without PyBullet's banner."""
    with native_output_silenced():
        return bullet_client.BulletClient(
            connection_mode=pybullet.DIRECT if mode is None else mode
        )
