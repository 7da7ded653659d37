"""Fixtures shared by the PyBullet tests."""

from __future__ import annotations

import pybullet
import pytest
from pybullet_utils import bullet_client


@pytest.fixture
def bc():
    """A fresh DIRECT PyBullet client, disconnected after the test."""
    client = bullet_client.BulletClient(connection_mode=pybullet.DIRECT)
    try:
        yield client
    finally:
        client.disconnect()
