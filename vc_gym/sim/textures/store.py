"""Loading texture images into a PyBullet client: :class:`TextureStore`.

PyBullet loads textures only from files. The store writes each image as a PNG into a
private temporary folder, loads it once into its client (``loadTexture`` memory is freed
only by ``resetSimulation``/``disconnect``), deletes the file right after loading and the
folder when it is closed.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
from collections.abc import Callable

import cv2
import numpy as np

__all__ = ["TEXTURE_DIR_PREFIX", "TextureStore"]

#: Prefix of the temporary folders texture files are written to.
TEXTURE_DIR_PREFIX = "vc_gym_textures_"


class TextureStore:
    """Loads images into one PyBullet client, each distinct image once.

    Create one store per scene build (after ``resetSimulation`` the ids are gone) and
    :meth:`close` it when the build is done (or use it as a context manager). Each image
    is written as a PNG into the store's own temporary folder, loaded with
    ``loadTexture`` and deleted at once; :meth:`close` removes the folder, so nothing is
    left behind however many scenes are built, even in worker processes that exit
    without running ``atexit`` handlers.

    Parameters
    ----------
    bc : pybullet_utils.bullet_client.BulletClient
        The client to load textures into.
    """

    def __init__(self, bc) -> None:
        self.bc = bc
        self._ids: dict[str, int] = {}
        self._dir: str | None = None
        self._count = 0

    def __enter__(self) -> TextureStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Remove the temporary folder (texture ids stay valid in the client)."""
        if self._dir is not None:
            shutil.rmtree(self._dir, ignore_errors=True)
            self._dir = None

    def __len__(self) -> int:
        return len(set(self._ids.values()))

    def load(self, key: str, make: Callable[[], np.ndarray]) -> int:
        """Texture id for ``key``, creating the image with ``make()`` the first time.

        Parameters
        ----------
        key : str
            Name of the texture within this store.
        make : callable
            Returns the ``(H, W, 3)`` ``uint8`` RGB image; called at most once per key.

        Returns
        -------
        int
            PyBullet texture id (for ``changeVisualShape(textureUniqueId=...)``).
        """
        if key not in self._ids:
            self._ids[key] = self.load_image(make())
        return self._ids[key]

    def load_image(self, image: np.ndarray) -> int:
        """Texture id of an image; the same pixels are loaded only once per store.

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W, 3)`` ``uint8`` RGB; row 0 is the top (texture ``v = 1``).

        Returns
        -------
        int
            PyBullet texture id.

        Raises
        ------
        ValueError
            If ``image`` is not an ``(H, W, 3)`` ``uint8`` array.
        RuntimeError
            If PyBullet cannot load the written file.
        """
        img = np.ascontiguousarray(image)
        if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] != 3:
            raise ValueError(
                f"texture must be an (H, W, 3) uint8 RGB image, got {img.shape} {img.dtype}"
            )
        digest = hashlib.sha1(img.tobytes(), usedforsecurity=False)
        digest.update(repr(img.shape).encode())
        key = "#" + digest.hexdigest()
        if key in self._ids:
            return self._ids[key]
        if self._dir is None:
            self._dir = tempfile.mkdtemp(prefix=TEXTURE_DIR_PREFIX)
        self._count += 1
        path = os.path.join(self._dir, f"{self._count}.png")
        try:
            bgr = cv2.cvtColor(img, cv2.COLOR_RGB2BGR)
            if not cv2.imwrite(path, bgr, [cv2.IMWRITE_PNG_COMPRESSION, 0]):
                raise OSError(f"could not write texture file {path}")
            tex = int(self.bc.loadTexture(path))
        finally:
            try:
                os.remove(path)
            except OSError:
                pass
        if tex < 0:
            raise RuntimeError(f"PyBullet could not load the texture written to {path}")
        self._ids[key] = tex
        return tex
