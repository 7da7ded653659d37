"""Tests of vc_gym.sim.textures.store: each image loaded once, no files left behind."""

from __future__ import annotations

import os

import numpy as np
import pytest

from vc_gym.sim import textures


def test_texture_store_loads_each_image_once(bc, private_tmp):
    img = textures.procedural_poster(np.random.default_rng(0), 32)
    with textures.TextureStore(bc) as store:
        t1 = store.load_image(img)
        t2 = store.load_image(img.copy())
        t3 = store.load("key", lambda: img)
        assert t1 == t2 == t3 >= 0 and len(store) == 1
        t4 = store.load_image(img[::-1].copy())
        assert t4 != t1 and len(store) == 2
        with pytest.raises(ValueError, match="uint8"):
            store.load_image(img.astype(np.float32))
        assert [p.name[: len(textures.TEXTURE_DIR_PREFIX)] for p in private_tmp.iterdir()] == [
            textures.TEXTURE_DIR_PREFIX
        ]
    assert os.listdir(private_tmp) == []
