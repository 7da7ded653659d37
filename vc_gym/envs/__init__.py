"""PyBullet world, robot, camera, Gymnasium envs and wrappers."""
