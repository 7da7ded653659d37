"""PyBullet's banner stays out of the output; everything else still shows."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from vc_gym.sim.bullet import connect, native_output_silenced


def test_native_writes_inside_the_block_are_dropped_and_outside_kept(capfd):
    os.write(1, b"before\n")
    with native_output_silenced():
        os.write(1, b"hidden out\n")
        os.write(2, b"hidden err\n")
    os.write(2, b"after\n")
    out, err = capfd.readouterr()
    assert out == "before\n" and err == "after\n"


def test_the_descriptors_come_back_when_the_block_raises(capfd):
    with pytest.raises(RuntimeError), native_output_silenced():
        raise RuntimeError("inside")
    os.write(1, b"visible\n")
    assert capfd.readouterr().out == "visible\n"


def test_importing_the_simulator_and_connecting_print_nothing():
    code = (
        "import vc_gym.sim, gymnasium as gym\n"
        "from vc_gym.sim.bullet import connect\n"
        "connect().disconnect()\n"
        "env = gym.make('vc_gym/AiboRoom-v0'); env.reset(seed=0); env.close()\n"
        "print('done')\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout == "done\n"
    assert "argv[0]" not in run.stderr and "build time" not in run.stderr


def test_a_client_works():
    client = connect()
    try:
        assert client.getConnectionInfo()["isConnected"] == 1
    finally:
        client.disconnect()
