"""Tests of the particle filter over planar poses (paper 3.5, eq. 17-21)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vc_gym.angles import wrap180
from vc_gym.filters.particle_filter import ParticleFilter, PoseEstimate
from vc_gym.filters.synthetic_sensors import GaussianPoseSensor, VonMisesHeadingSensor

#: A 6 m x 4 m field centred on the origin.
FIELD = (-3.0, 3.0, -2.0, 2.0)


class FixedSensor:
    """A pose sensor that answers a fixed array, whatever it is asked."""

    def __init__(self, ll):
        self.ll = ll

    def pose_log_likelihood(self, observation, poses):
        return self.ll


def pos_err(est: PoseEstimate, pose) -> float:
    return math.hypot(est.x - pose[0], est.y - pose[1])


def head_err(est: PoseEstimate, pose) -> float:
    return abs(wrap180(est.heading_deg - pose[2]))


def move(pose, forward: float, left: float, dtheta: float) -> np.ndarray:
    """Exact robot-frame motion of a single pose (the ground truth)."""
    x, y, th = pose
    r = math.radians(th)
    return np.array(
        [
            x + forward * math.cos(r) - left * math.sin(r),
            y + forward * math.sin(r) + left * math.cos(r),
            (th + dtheta) % 360.0,
        ]
    )


def localise(pf: ParticleFilter, sensor, pose, rng, steps: int, noise=(0.02, 0.02, 2.0)) -> None:
    """A robot standing still: ``steps`` times predict (zero odometry) and update."""
    for _ in range(steps):
        pf.predict((0.0, 0.0, 0.0), noise)
        pf.update(sensor, sensor.read(pose, rng))


# ----------------------------------------------------------------------------- behaviour


def test_global_localisation_from_uniform_start():
    pf = ParticleFilter(2000, bounds=FIELD, rng=np.random.default_rng(1))
    sensor = GaussianPoseSensor(pos_noise_m=0.1, heading_noise_deg=5.0)
    true = np.array([1.2, -0.7, 135.0])
    start = pf.estimate()
    assert start.std_xy[0] > 1.5 and start.std_xy[1] > 1.0  # uniform over the field
    localise(pf, sensor, true, np.random.default_rng(101), steps=20, noise=(0.02, 0.02, 1.0))
    est = pf.estimate()
    assert pos_err(est, true) < 0.15
    assert head_err(est, true) < 5.0
    assert max(est.std_xy) < 0.15 and est.spread_deg < 5.0
    assert 1.0 <= est.ess <= pf.n_particles


def test_tracks_robot_driving_a_circle_with_biased_odometry():
    rng = np.random.default_rng(102)
    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(2))
    sensor = GaussianPoseSensor(pos_noise_m=0.2, heading_noise_deg=10.0)
    true = np.array([1.0, 0.0, 90.0])
    dead_reckoning = true.copy()
    pf.reset(tuple(true), (0.1, 0.1, 5.0))
    forward, turn = 0.1, math.degrees(0.1)  # a circle of radius 1 m, ~2 laps
    errs, herrs, dr_errs = [], [], []
    for _ in range(120):
        true = move(true, forward, 0.0, turn)
        # odometry overestimates by 10% and is noisy
        odo = (
            1.1 * forward + rng.normal(0, 0.01),
            rng.normal(0, 0.01),
            1.1 * turn + rng.normal(0, 1.0),
        )
        dead_reckoning = move(dead_reckoning, *odo)
        pf.predict(odo, (0.02, 0.02, 2.0))
        pf.update(sensor, sensor.read(true, rng))
        est = pf.estimate()
        errs.append(pos_err(est, true))
        herrs.append(head_err(est, true))
        dr_errs.append(math.hypot(*(dead_reckoning[:2] - true[:2])))
    assert np.mean(errs[10:]) < 0.15  # the sensor alone has 0.2 m noise per axis
    assert np.max(errs[10:]) < 0.35
    assert np.mean(herrs[10:]) < 6.0
    assert np.mean(errs[10:]) < 0.5 * np.mean(dr_errs[10:])  # better than odometry alone


def test_heading_only_sensor_converges_heading_not_position():
    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(3))
    sensor = VonMisesHeadingSensor(noise_deg=5.0)
    rng = np.random.default_rng(103)
    for _ in range(20):
        pf.predict((0.0, 0.0, 0.0))
        pf.update(sensor, sensor.read(200.0, rng))
    est = pf.estimate()
    assert head_err(est, (0.0, 0.0, 200.0)) < 8.0
    assert est.spread_deg < 8.0
    # x and y carry no information: they stay about uniform (std 1.73 m and 1.15 m)
    assert est.std_xy[0] > 1.0 and est.std_xy[1] > 0.7


def _kidnap(inject_fraction: float) -> tuple[PoseEstimate, PoseEstimate, np.ndarray, np.ndarray]:
    pf = ParticleFilter(
        1000, bounds=FIELD, rng=np.random.default_rng(4), inject_fraction=inject_fraction
    )
    sensor = GaussianPoseSensor(pos_noise_m=0.2, heading_noise_deg=10.0)
    rng = np.random.default_rng(104)
    a = np.array([-2.0, 1.2, 30.0])
    b = np.array([2.0, -1.3, 250.0])
    localise(pf, sensor, a, rng, steps=20)
    at_a = pf.estimate()
    localise(pf, sensor, b, rng, steps=40)  # kidnapped: the robot is now at b
    return at_a, pf.estimate(), a, b


def test_kidnapping_recovery_with_injection():
    at_a, at_b, a, b = _kidnap(0.05)
    assert pos_err(at_a, a) < 0.3 and head_err(at_a, a) < 10.0
    assert pos_err(at_b, b) < 0.3 and head_err(at_b, b) < 15.0


def test_no_kidnapping_recovery_without_injection():
    at_a, at_b, a, b = _kidnap(0.0)
    assert pos_err(at_a, a) < 0.3
    assert pos_err(at_b, b) > 1.0  # stuck: no particle near b and the motion noise is small


def test_injection_count_and_bounds():
    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(5), inject_fraction=0.05)
    pf.reset((10.0, 10.0, 0.0))  # all particles outside the field
    pf.resample()
    p = pf.particles
    injected = ~np.all(p == np.array([10.0, 10.0, 0.0]), axis=1)
    assert injected.sum() == 50
    q = p[injected]
    assert np.all((q[:, 0] >= -3) & (q[:, 0] <= 3) & (q[:, 1] >= -2) & (q[:, 1] <= 2))
    assert np.all((q[:, 2] >= 0) & (q[:, 2] < 360))
    np.testing.assert_allclose(pf.weights, 1e-3)


# ----------------------------------------------------------------------------- motion model


def test_predict_applies_odometry_in_each_particles_frame():
    pf = ParticleFilter(4, rng=np.random.default_rng(6))
    pf.reset((1.0, 2.0, 90.0))  # facing north
    pf.predict((1.0, 0.5, 30.0), noise=(0.0, 0.0, 0.0))
    # forward 1 m = north, left 0.5 m = west
    np.testing.assert_allclose(pf.particles, [[0.5, 3.0, 120.0]] * 4, atol=1e-12)
    pf.predict((0.0, 0.0, 250.0), noise=(0.0, 0.0, 0.0))
    np.testing.assert_allclose(pf.particles[:, 2], 10.0, atol=1e-9)  # 370 wrapped


def test_predict_noise_statistics():
    pf = ParticleFilter(20000, rng=np.random.default_rng(7))
    pf.reset((0.0, 0.0, 0.0))
    pf.predict((1.0, 0.0, 0.0), noise=(0.1, 0.05, 3.0))
    p = pf.particles
    assert p[:, 0].mean() == pytest.approx(1.0, abs=0.005)
    assert p[:, 0].std() == pytest.approx(0.1, rel=0.03)
    assert p[:, 1].std() == pytest.approx(0.05, rel=0.03)
    assert np.std(wrap180(p[:, 2])) == pytest.approx(3.0, rel=0.03)
    assert np.all((p[:, 2] >= 0.0) & (p[:, 2] < 360.0))


def test_predict_does_not_clip_to_bounds():
    pf = ParticleFilter(100, bounds=FIELD, rng=np.random.default_rng(8))
    pf.reset((2.9, 0.0, 0.0))
    pf.predict((1.0, 0.0, 0.0), noise=(0.0, 0.0, 0.0))
    np.testing.assert_allclose(pf.particles[:, 0], 3.9)


# ----------------------------------------------------------------------------- estimate


def test_circular_mean_across_zero():
    pf = ParticleFilter(2000, rng=np.random.default_rng(9))
    pf.reset((0.0, 0.0, -1.0), (0.1, 0.1, 3.0))  # headings around 359 and 1
    th = pf.particles[:, 2]
    assert np.all((th >= 0.0) & (th < 360.0))
    assert (th > 350).any() and (th < 10).any()
    est = pf.estimate()
    assert abs(wrap180(est.heading_deg + 1.0)) < 0.5  # near 359, not 180
    assert est.spread_deg == pytest.approx(3.0, rel=0.1)


def test_estimate_is_weighted():
    pf = ParticleFilter(2, rng=np.random.default_rng(10), resample_threshold=0.0)
    pf.reset((0.0, 0.0, 0.0))
    pf.predict((0.0, 0.0, 0.0), noise=(0.0, 0.0, 0.0))
    pf.update(FixedSensor(np.log([0.75, 0.25])), None)
    # identical particles: the estimate is that pose with zero spread
    est = pf.estimate()
    assert (est.x, est.y, est.std_xy) == (0.0, 0.0, (0.0, 0.0))
    assert est.ess == pytest.approx(1.0 / (0.75**2 + 0.25**2))


# ----------------------------------------------------------------------------- resampling


def test_resample_onto_single_particle():
    pf = ParticleFilter(500, bounds=FIELD, rng=np.random.default_rng(11), resample_threshold=0.0)
    ll = np.full(500, -np.inf)
    ll[123] = 0.0
    chosen = pf.particles[123]
    assert pf.update(FixedSensor(ll), None) == pytest.approx(1.0)
    pf.resample()
    np.testing.assert_array_equal(pf.particles, np.tile(chosen, (500, 1)))
    np.testing.assert_allclose(pf.weights, 1 / 500)


def test_resample_preserves_weighted_mean_and_is_low_variance():
    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(12), resample_threshold=0.0)
    sensor = GaussianPoseSensor(pos_noise_m=1.0, heading_noise_deg=None)
    pf.update(sensor, np.array([1.0, 0.5, 0.0]))
    before, w = pf.particles, pf.weights
    mean_before = w @ before[:, :2]
    std_before = np.sqrt(w @ (before[:, :2] - mean_before) ** 2)
    pf.resample()
    after = pf.particles
    # well within the standard error of multinomial resampling, std / sqrt(N)
    err = np.abs(after[:, :2].mean(axis=0) - mean_before)
    assert np.all(err < 2.5 * std_before / math.sqrt(1000))
    # systematic resampling copies particle i floor(N w_i) or ceil(N w_i) times
    order = np.argsort(before[:, 0])
    idx = order[np.searchsorted(before[order, 0], after[:, 0])]
    np.testing.assert_array_equal(before[idx], after)
    counts = np.bincount(idx, minlength=1000)
    assert np.all(counts >= np.floor(1000 * w) - 1e-9)
    assert np.all(counts <= np.ceil(1000 * w) + 1e-9)


def test_update_resamples_automatically_below_threshold():
    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(13), resample_threshold=0.5)
    sensor = GaussianPoseSensor(pos_noise_m=0.3, heading_noise_deg=None)
    ess = pf.update(sensor, np.array([0.0, 0.0, 0.0]))
    assert ess < 500  # reported before resampling
    np.testing.assert_allclose(pf.weights, 1e-3)
    assert pf.ess == pytest.approx(1000)
    assert pf.ess <= 1000  # no round-off above N

    pf = ParticleFilter(1000, bounds=FIELD, rng=np.random.default_rng(13), resample_threshold=0.0)
    ess = pf.update(sensor, np.array([0.0, 0.0, 0.0]))
    assert pf.ess == pytest.approx(ess)  # never resampled
    assert pf.weights.std() > 0


def _run(seed: int, inject: float = 0.05) -> ParticleFilter:
    pf = ParticleFilter(300, bounds=FIELD, rng=np.random.default_rng(seed), inject_fraction=inject)
    sensor = GaussianPoseSensor(0.2, 10.0)
    for k in range(5):
        pf.predict((0.1, 0.0, 5.0))
        pf.update(sensor, np.array([0.1 * k, 0.0, 5.0 * k]))
    pf.resample()
    return pf


def test_same_seed_same_particles():
    a, b = _run(14), _run(14)
    np.testing.assert_array_equal(a.particles, b.particles)
    np.testing.assert_array_equal(a.weights, b.weights)
    assert not np.array_equal(a.particles, _run(15).particles)
    # reset(rng=...) re-seeds the whole filter
    a.reset(rng=np.random.default_rng(99))
    b.reset(rng=np.random.default_rng(99))
    np.testing.assert_array_equal(a.particles, b.particles)


def test_default_rng_is_seeded():
    a = ParticleFilter(50, bounds=FIELD)
    b = ParticleFilter(50, bounds=FIELD)
    np.testing.assert_array_equal(a.particles, b.particles)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.one_of(st.floats(-50.0, 50.0), st.just(-math.inf)), min_size=1, max_size=200
    ).filter(lambda ll: any(math.isfinite(v) for v in ll)),
    st.integers(0, 2**32 - 1),
)
def test_resample_gives_uniform_weights_and_keeps_count(ll, seed):
    n = len(ll)
    pf = ParticleFilter(n, bounds=FIELD, rng=np.random.default_rng(seed), resample_threshold=0.0)
    pf.update(FixedSensor(np.array(ll)), None)
    before, w = pf.particles, pf.weights
    pf.resample()
    after = pf.particles
    assert after.shape == (n, 3)
    np.testing.assert_allclose(pf.weights, 1.0 / n)
    assert pf.ess == pytest.approx(n)
    # only particles with positive weight survive
    alive = before[w > 0]
    assert all(np.any(np.all(alive == row, axis=1)) for row in after)


# ----------------------------------------------------------------------------- robustness


def test_all_impossible_keeps_belief_and_warns():
    pf = ParticleFilter(200, bounds=FIELD, rng=np.random.default_rng(16), resample_threshold=0.0)
    pf.update(GaussianPoseSensor(1.0, None), np.array([0.0, 0.0, 0.0]))
    before_p, before_w, before_ess = pf.particles, pf.weights, pf.ess
    with pytest.warns(RuntimeWarning, match="-inf"):
        ess = pf.update(FixedSensor(np.full(200, -np.inf)), None)
    assert ess == before_ess
    np.testing.assert_array_equal(pf.particles, before_p)
    np.testing.assert_array_equal(pf.weights, before_w)


def test_impossible_for_all_weighted_particles_also_keeps_belief():
    pf = ParticleFilter(4, rng=np.random.default_rng(17), resample_threshold=0.0)
    pf.update(FixedSensor(np.array([0.0, -np.inf, -np.inf, -np.inf])), None)
    with pytest.warns(RuntimeWarning):
        pf.update(FixedSensor(np.array([-np.inf, 0.0, 0.0, 0.0])), None)
    np.testing.assert_array_equal(pf.weights, [1.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize(
    "ll",
    [
        np.array([0.0, np.nan, 0.0]),
        np.array([0.0, np.inf, 0.0]),
        np.zeros(2),
        np.zeros((3, 1)),
    ],
    ids=["nan", "+inf", "short", "2d"],
)
def test_bad_likelihoods_raise(ll):
    pf = ParticleFilter(3, rng=np.random.default_rng(18))
    with pytest.raises(ValueError, match="FixedSensor"):
        pf.update(FixedSensor(ll), None)
    np.testing.assert_allclose(pf.weights, 1 / 3)


def test_sensor_gets_read_only_particles():
    class Vandal:
        def pose_log_likelihood(self, observation, poses):
            poses[:, 0] = 0.0
            return np.zeros(len(poses))

    pf = ParticleFilter(3, rng=np.random.default_rng(19))
    with pytest.raises(ValueError, match="read-only"):
        pf.update(Vandal(), None)


def test_properties_are_copies():
    pf = ParticleFilter(10, bounds=FIELD, rng=np.random.default_rng(20))
    pf.particles[:] = 0.0
    pf.weights[:] = 0.0
    assert pf.particles.any() and pf.weights.sum() == pytest.approx(1.0)


def test_single_particle():
    pf = ParticleFilter(1, bounds=FIELD, rng=np.random.default_rng(21))
    pf.predict((0.1, 0.0, 1.0))
    assert pf.update(GaussianPoseSensor(), np.array([0.0, 0.0, 0.0])) == pytest.approx(1.0)
    pf.resample()
    assert pf.estimate().ess == pytest.approx(1.0)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"n_particles": 0},
        {"n_particles": 2.5},
        {"n_particles": True},
        {"bounds": (0.0, 0.0, -1.0, 1.0)},
        {"bounds": (1.0, -1.0, -1.0, 1.0)},
        {"bounds": (0.0, np.inf, -1.0, 1.0)},
        {"bounds": (0.0, 1.0, -1.0)},
        {"resample_threshold": -0.1},
        {"resample_threshold": 1.5},
        {"inject_fraction": 1.0, "bounds": FIELD},
        {"inject_fraction": -0.1, "bounds": FIELD},
        {"inject_fraction": 0.05},  # no bounds to inject from
        {"rng": 0},
        {"rng": np.random.RandomState(0)},
    ],
)
def test_constructor_validation(kwargs):
    with pytest.raises(ValueError):
        ParticleFilter(**kwargs)


def test_call_validation():
    pf = ParticleFilter(10, rng=np.random.default_rng(22))
    with pytest.raises(ValueError, match="noise"):
        pf.predict((0.1, 0.0, 0.0), noise=(0.01, -0.01, 1.0))
    with pytest.raises(ValueError, match="noise"):
        pf.predict((0.1, 0.0, 0.0), noise=(0.01, 0.01, np.nan))
    with pytest.raises(ValueError, match="odometry"):
        pf.predict((np.inf, 0.0, 0.0))
    with pytest.raises(ValueError, match="odometry"):
        pf.predict((0.1, 0.0))
    with pytest.raises(ValueError, match="bounds"):
        pf.reset()  # uniform needs bounds
    with pytest.raises(ValueError, match="mean"):
        pf.reset((0.0, np.nan, 0.0))
    with pytest.raises(ValueError, match="std"):
        pf.reset((0.0, 0.0, 0.0), (0.1, -0.1, 1.0))
    with pytest.raises(ValueError, match="std"):
        pf.reset(std=(0.1, 0.1, 1.0))
    with pytest.raises(ValueError, match="rng"):
        pf.reset((0.0, 0.0, 0.0), rng=np.random.RandomState(0))


def test_replace_overwrites_chosen_particles_only():
    pf = ParticleFilter(10, bounds=(-1, 1, -1, 1), rng=np.random.default_rng(0))
    before, w = pf.particles, pf.weights
    pf.replace(np.array([2, 5]), np.array([[0.5, 0.5, 370.0], [-0.5, 0.0, -10.0]]))
    after = pf.particles
    np.testing.assert_allclose(after[[2, 5]], [[0.5, 0.5, 10.0], [-0.5, 0.0, 350.0]])
    keep = np.setdiff1d(np.arange(10), [2, 5])
    np.testing.assert_array_equal(after[keep], before[keep])
    np.testing.assert_array_equal(pf.weights, w)
    for idx, poses in (
        (np.array([10]), np.zeros((1, 3))),
        (np.array([1, 1]), np.zeros((2, 3))),
        (np.array([0.5]), np.zeros((1, 3))),
        (np.array([0]), np.zeros((2, 3))),
        (np.array([0]), np.array([[np.nan, 0, 0]])),
    ):
        with pytest.raises(ValueError):
            pf.replace(idx, poses)


def test_resampling_injects_poses_from_a_given_sampler():
    pf = ParticleFilter(
        100, bounds=(-1, 1, -1, 1), rng=np.random.default_rng(0), inject_fraction=0.1
    )
    asked = []

    def at_the_corner(k):
        asked.append(k)
        return np.tile([5.0, 5.0, 90.0], (k, 1))

    # a sharp sensor: the ESS collapses, so this update resamples and injects
    pf.update(GaussianPoseSensor(0.05, None), np.array([0.0, 0.0, 0.0]), inject=at_the_corner)
    assert asked == [10]
    corner = np.all(pf.particles == [5.0, 5.0, 90.0], axis=1)
    assert corner.sum() == 10
    pf.update(GaussianPoseSensor(50.0, None), np.array([0.0, 0.0, 0.0]), inject=at_the_corner)
    assert asked == [10]  # a flat sensor: no resampling, nothing injected
    with pytest.raises(ValueError):
        pf.resample(inject=lambda k: np.zeros((k, 2)))


@pytest.mark.parametrize(
    ("odometry", "noise"),
    [((1e308, 0.0, 0.0), (0.0, 0.0, 0.0)), ((0.0, 0.0, 0.0), (0.0, 0.0, 1e300))],
)
def test_motion_beyond_physical_limits_is_refused(odometry, noise):
    # odometry of 1e308 m is refused, not turned silently into a NaN estimate
    pf = ParticleFilter(100, rng=np.random.default_rng(0))
    pf.reset(mean=(0.0, 0.0, 0.0), std=(0.1, 0.1, 5.0))
    with pytest.raises(ValueError, match="within"):
        pf.predict(odometry, noise)
    e = pf.estimate()
    assert np.isfinite(e.x) and np.isfinite(e.y)
