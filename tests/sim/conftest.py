"""Fixtures shared by the PyBullet tests."""

from __future__ import annotations

import tempfile

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


@pytest.fixture
def private_tmp(tmp_path, monkeypatch):
    """Make ``tempfile`` write into an empty folder of this test only."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    return tmp_path
