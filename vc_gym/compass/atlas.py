"""Several compasses learned at several spots: goodness of fit and position (eq. 28-30).

One :class:`VisualCompass` map per training spot ``T_i``. For an image, each map's
goodness ``L_i`` (eq. 28) says how well the image fits what was seen at that spot;
after normalising the ``L_i`` so that they are equal at the home spot (paper 5.2),
the position estimate is the likelihood-weighted mean of the spots (eq. 30).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vc_gym.compass.camera import Camera
from vc_gym.compass.colors import ColorClasses
from vc_gym.compass.config import MAX_MAP_BYTES, CompassConfig
from vc_gym.compass.landmarks import LandmarkMap
from vc_gym.compass.likelihood import log_likelihoods
from vc_gym.compass.visual_compass import CompassEstimate, VisualCompass, _estimates_of
from vc_gym.errors import MapFileError, NotLearnedError
from vc_gym.exposure import SessionLight
from vc_gym.persistence import json_array, load_npz_checked, read_json_array, save_npz_atomic
from vc_gym.validation import MAX_ABS_METRES, finite_real

__all__ = [
    "CompassAtlas",
    "AtlasEstimate",
    "MAX_ATLAS_BYTES",
    "MAX_KERNEL_DEG",
    "MAX_SHARPNESS",
    "MAX_SPOTS",
    "MIN_KERNEL_DEG",
    "MIN_SHARPNESS",
]

ATLAS_SCHEMA = "vc_gym.CompassAtlas"
ATLAS_SCHEMA_VERSION = 1
#: Most spots an atlas may hold (a guard against a hostile header; an atlas file of
#: this many spots stays within :data:`vc_gym.persistence.MAX_MEMBERS` entries).
MAX_SPOTS = 1024
#: Most memory loading an atlas and scoring one frame with all its maps may take, as
#: :meth:`CompassConfig.memory_bytes` reckons it for the atlas' spots (two single maps'
#: worth, 1 GiB): every map's tables are kept, so a file of a megabyte (24 maps of
#: 32 classes and bins) could otherwise claim two gigabytes.
MAX_ATLAS_BYTES = 2 * MAX_MAP_BYTES
#: Range of :attr:`CompassAtlas.sharpness`: below 0.01 every spot weighs the same
#: (eq. 30 returns the centroid whatever the image), far above 10,000 the weights
#: of spots a hundredth apart in goodness overflow.
MIN_SHARPNESS = 0.01
MAX_SHARPNESS = 1e4
#: Range of the home normalisation's kernel width (degrees): finer than the finest
#: heading grid, its concentration overflows.
MIN_KERNEL_DEG = 0.01
MAX_KERNEL_DEG = 360.0


@dataclass(frozen=True)
class AtlasEstimate:
    """What the atlas says about one image.

    Attributes
    ----------
    position : tuple of float
        Likelihood-weighted mean of the spot positions (eq. 30), world ``(x, y)``.
    goodness : dict
        Normalised goodness ``L̂_i`` per spot name, for the spots scored (1.0 for every
        spot at home after :meth:`CompassAtlas.normalize`; larger means the image fits
        that spot better).
    weights : dict
        The weights of eq. 30 per spot (sum to 1).
    estimates : dict
        Each spot's own :class:`CompassEstimate` (heading, spread, score, ...).
    """

    position: tuple[float, float]
    goodness: dict[str, float]
    weights: dict[str, float]
    estimates: dict[str, CompassEstimate]


class CompassAtlas:
    """Compasses learned at several spots, for goodness-of-fit and position (eq. 28-30).

    Parameters
    ----------
    spots : mapping
        ``{name: ((x, y), compass)}``: the training spot ``T_i`` in world metres and
        the :class:`VisualCompass` learned there. All compasses must share one config.
    home : str
        Name of the home (target) spot. It may be one of the spots or a place of its
        own; :meth:`normalize` is meant to be called with images taken there.
    home_position : tuple of float, optional
        World position of home. Defaults to the named spot's position, or to the
        centroid of the spots when ``home`` is not a spot.
    sharpness : float
        Exponent applied to the goodness before weighting, in
        ``[MIN_SHARPNESS, MAX_SHARPNESS]``. Larger values make the position estimate
        snap to the best-fitting spot, smaller ones pull it to the centroid. The
        default 30 was measured on a synthetic 7 m room at the paper's
        config with spots 1 m from home: a frame 1 m from home is then placed about
        0.7 m from home in the right direction (``tests/compass/test_atlas.py``).

    Notes
    -----
    The paper takes ``L_i`` as the maximal likelihood of the image under map ``i``
    (eq. 28). Raw likelihoods are products over hundreds of terms and overflow, so
    here ``L_i = exp(score_i)`` with ``score_i`` the mean log-probability per term at
    the best heading (:attr:`CompassEstimate.score`), i.e. a geometric mean.
    """

    def __init__(
        self,
        spots: Mapping[str, tuple[tuple[float, float], VisualCompass]],
        home: str,
        home_position: tuple[float, float] | None = None,
        sharpness: float = 30.0,
    ):
        if not isinstance(spots, Mapping) or len(spots) == 0:
            raise ValueError("spots must be a non-empty mapping {name: ((x, y), compass)}")
        names: list[str] = []
        positions: list[tuple[float, float]] = []
        compasses: list[VisualCompass] = []
        for name, entry in spots.items():
            try:
                pos, vc = entry
                x, y = (float(v) for v in pos)
            except (TypeError, ValueError):
                raise ValueError(
                    f"spot {name!r} must be ((x, y), VisualCompass), got {entry!r}"
                ) from None
            if not (math.isfinite(x) and math.isfinite(y)) or max(abs(x), abs(y)) > MAX_ABS_METRES:
                raise ValueError(
                    f"spot {name!r} position must be finite and within ±{MAX_ABS_METRES:g} m, "
                    f"got {(x, y)}"
                )
            if not isinstance(vc, VisualCompass):
                raise ValueError(f"spot {name!r} needs a VisualCompass, got {type(vc).__name__}")
            names.append(str(name))
            positions.append((x, y))
            compasses.append(vc)
        configs = {vc.config for vc in compasses}
        if len(configs) > 1:
            raise ValueError("all compasses of an atlas must share one CompassConfig")
        _check_atlas_size(
            compasses[0].config, len(compasses), len({id(vc.colors) for vc in compasses})
        )
        self.names = tuple(names)
        self.positions = np.array(positions, dtype=np.float64)
        self.compasses = tuple(compasses)
        self.home = str(home)
        if home_position is None:
            if self.home in self.names:
                home_position = tuple(self.positions[self.names.index(self.home)])
            else:
                home_position = tuple(self.positions.mean(axis=0))
        hx, hy = (float(v) for v in home_position)
        if not (math.isfinite(hx) and math.isfinite(hy)) or max(abs(hx), abs(hy)) > MAX_ABS_METRES:
            raise ValueError(
                f"home_position must be finite and within ±{MAX_ABS_METRES:g} m, "
                f"got {home_position}"
            )
        self.home_position = (hx, hy)
        sharp = finite_real("sharpness", sharpness)
        if not MIN_SHARPNESS <= sharp <= MAX_SHARPNESS:
            raise ValueError(
                f"sharpness must be in [{MIN_SHARPNESS:g}, {MAX_SHARPNESS:g}], got {sharpness!r}"
            )
        self.sharpness = sharp
        self._home_scores = np.zeros((0, len(names)))
        self._home_headings = np.zeros((0, len(names)))
        self._kappa = 1.0
        #: The colour changes of the learning turns placed in the room
        #: (:func:`~vc_gym.compass.landmarks.learn_landmarks`), if they were learned;
        #: saved with the atlas.
        self.landmarks: LandmarkMap | None = None
        self.is_normalized = False
        self._stacked: tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray] | None = None

    def __len__(self) -> int:
        return len(self.names)

    def subset(self, names: Sequence[str]) -> CompassAtlas:
        """The atlas of the spots ``names`` only (in that order), with the same home,
        sharpness and normalisation: each kept spot scores a frame, and is normalised,
        exactly as in this atlas.

        Raises
        ------
        ValueError
            If ``names`` is empty, repeats a spot or names one this atlas lacks.
        """
        names = [str(n) for n in names]
        unknown = sorted(set(names) - set(self.names))
        if not names or unknown or len(set(names)) != len(names):
            raise ValueError(
                f"subset needs distinct spots of the atlas {list(self.names)}, got {names}"
            )
        index = [self.names.index(n) for n in names]
        out = CompassAtlas(
            {
                n: (tuple(self.positions[k]), self.compasses[k])
                for n, k in zip(names, index, strict=True)
            },
            home=self.home,
            home_position=self.home_position,
            sharpness=self.sharpness,
        )
        out._home_scores = self._home_scores[:, index].copy()
        out._home_headings = self._home_headings[:, index].copy()
        out._kappa = self._kappa
        out.is_normalized = self.is_normalized
        return out

    def scores(
        self,
        image: np.ndarray,
        camera: Camera,
        spots: Sequence[int] | None = None,
        gain: float | None = None,
    ) -> tuple[np.ndarray, list[CompassEstimate]]:
        """Raw per-spot scores (mean log-probability per term) and estimates.

        ``spots`` (indices into :attr:`names`) scores only those spots' maps, in that
        order; each equals its entry of the full answer bit for bit. ``gain`` is the
        session's light, as in :meth:`VisualCompass.log_likelihood`.
        """
        which = self._spot_indices(spots)
        return self._scores_of(image, camera, which, every=spots is None, gain=gain)

    def frame_gain(self, image: np.ndarray, camera: Camera) -> float:
        """:meth:`VisualCompass.frame_gain` of the first spot's map (an atlas' maps share
        their colour classes and so their reference level)."""
        return self.compasses[0].frame_gain(image, camera)

    def _scores_of(
        self,
        image: np.ndarray,
        camera: Camera,
        which: np.ndarray,
        every: bool,
        gain: float | None = None,
    ) -> tuple[np.ndarray, list[CompassEstimate]]:
        """:meth:`scores` of the checked spot indices ``which`` (``every``: all of them,
        in order, so the stacked tables are read whole)."""
        compasses = [self.compasses[k] for k in which]
        first = compasses[0]
        if first.config.exposure != "map" and all(
            vc.colors is first.colors for vc in self.compasses
        ):
            # one colour set and config (the usual case): the image's sector features
            # are the same for every spot, so compute them once (not with
            # exposure="map": every map brings the frame to its own learned light)
            for vc in compasses:
                vc._checked(image, camera, need_map=True)
            g = first._gain_for(image, camera, first._checked_gain(gain))
            features = first._sector_features(image, camera, g)
            delta_t, base = self._stacked_tables()
            maps = None if every else which
            lls = log_likelihoods(first.config, *features, delta_t, base, maps)
            ests = _estimates_of(compasses, *features, lls)
        else:
            ests = [vc.estimate(image, camera, gain=gain) for vc in compasses]
        return np.array([e.score for e in ests]), ests

    def _spot_indices(self, spots: Sequence[int] | None) -> np.ndarray:
        """``spots`` checked: distinct in-range indices (every spot when ``None``)."""
        if spots is None:
            return np.arange(len(self.names))
        try:
            which = np.asarray(spots)
            ok = which.ndim == 1 and which.size > 0 and np.issubdtype(which.dtype, np.integer)
        except (TypeError, ValueError):
            ok = False
        if not ok or which.min() < 0 or which.max() >= len(self.names):
            raise ValueError(
                f"spots must be a non-empty sequence of spot indices in [0, {len(self.names)}),"
                f" got {spots!r}"
            )
        if np.unique(which).size != which.size:
            raise ValueError(f"spots must not repeat an index, got {spots!r}")
        return which.astype(np.intp)

    def _stacked_tables(self) -> tuple[np.ndarray, np.ndarray]:
        """Every map's log tables stacked (``(c²·n, M, S)``, ``(M, S)``), rebuilt only
        when a map's tables changed (a compass that learned more)."""
        tables = [vc._log_tables() for vc in self.compasses]
        deltas = tuple(t[0] for t in tables)
        cached = self._stacked
        if cached is None or any(a is not b for a, b in zip(cached[0], deltas, strict=True)):
            cached = (deltas, np.stack(deltas, axis=1), np.stack([t[1] for t in tables]))
            self._stacked = cached
        return cached[1], cached[2]

    def normalize(
        self,
        images: Sequence[np.ndarray],
        cameras: Sequence[Camera],
        kernel_deg: float = 30.0,
    ) -> np.ndarray:
        """Normalise the goodness so that every spot reports 1 at home (paper 5.2).

        How well a frame fits a spot's map depends on where the camera looks (a wall
        close by changes more with a step than a far one), so the home level is
        remembered per heading: each spot keeps the score and its own heading
        estimate of every home frame, and a later frame is normalised by the
        home scores near the heading that spot estimates for it (a von Mises kernel
        of width ``kernel_deg``). Frames from a full turn at home are best.

        Parameters
        ----------
        images, cameras : sequences of equal length
            Frames taken at the home spot (with ``exposure="session"`` one session,
            scored at its :class:`~vc_gym.exposure.SessionLight`).
        kernel_deg : float
            Angular width of the interpolation between home frames, in
            ``[MIN_KERNEL_DEG, MAX_KERNEL_DEG]``.

        Returns
        -------
        numpy.ndarray
            The mean home score of each spot (log domain).
        """
        if isinstance(images, np.ndarray) and images.ndim == 3:
            images = [images]
        if isinstance(cameras, Camera):
            cameras = [cameras] * len(images)
        if len(images) == 0 or len(images) != len(cameras):
            raise ValueError(
                f"normalize needs as many cameras as images (>0), got {len(images)} images "
                f"and {len(cameras)} cameras"
            )
        kernel = finite_real("kernel_deg", kernel_deg)
        if not MIN_KERNEL_DEG <= kernel <= MAX_KERNEL_DEG:
            raise ValueError(
                f"kernel_deg must be in [{MIN_KERNEL_DEG:g}, {MAX_KERNEL_DEG:g}], got {kernel_deg}"
            )
        gain = None
        if self.compasses[0].config.exposure == "session":  # the home frames: one session
            pairs = zip(images, cameras, strict=True)
            gain = SessionLight.of(self.frame_gain(img, cam) for img, cam in pairs)
        scores, headings = [], []
        for img, cam in zip(images, cameras, strict=True):
            raw, ests = self.scores(img, cam, gain=gain)
            scores.append(raw)
            headings.append([e.heading_deg for e in ests])
        self._home_scores = np.array(scores)  # (frames, spots)
        self._home_headings = np.array(headings)
        self._kappa = _kappa_of(kernel)
        self.is_normalized = True
        return self._home_scores.mean(axis=0)

    def home_scores(
        self, headings_deg: np.ndarray, spots: Sequence[int] | None = None
    ) -> np.ndarray:
        """Home score of each spot at the given per-spot headings (0 before normalize);
        ``spots`` as in :meth:`scores`."""
        return self._home_scores_of(headings_deg, self._spot_indices(spots))

    def _home_scores_of(self, headings_deg: np.ndarray, which: np.ndarray) -> np.ndarray:
        """:meth:`home_scores` of the checked spot indices ``which``."""
        if not self.is_normalized:
            return np.zeros(which.size)
        home_headings = self._home_headings[:, which]
        d = np.radians(np.asarray(headings_deg)[None, :] - home_headings)
        logw = self._kappa * (np.cos(d) - 1.0)  # (frames, spots)
        # relative to the nearest home frame, which weighs 1: even a narrow kernel cannot
        # underflow every weight to 0 (0 / 0 would make the position NaN)
        w = np.exp(logw - logw.max(axis=0, keepdims=True))
        return (w * self._home_scores[:, which]).sum(axis=0) / w.sum(axis=0)

    def estimate_position(
        self,
        image: np.ndarray,
        camera: Camera,
        spots: Sequence[int] | None = None,
        gain: float | None = None,
    ) -> AtlasEstimate:
        """Position from the goodness of every spot (eq. 28-30).

        ``L̂_i = exp(score_i - home_score_i)`` (home score at spot ``i``'s heading
        estimate, see :meth:`normalize`), weights ``∝ L̂_i ** sharpness``, position
        ``= Σ w_i T_i``. Before :meth:`normalize` the home scores are zero.

        ``spots`` (indices into :attr:`names`) limits eq. 28-30 to those spots: only
        their maps are read (the cost grows with their number), and the estimate's
        dictionaries hold only them (a tracker can score only the few spots that fitted
        best a moment ago). ``gain`` is the session's light, as in
        :meth:`VisualCompass.log_likelihood` (a tracker keeps it, see
        :class:`~vc_gym.exposure.SessionLight`).
        """
        if any(not vc.is_learned for vc in self.compasses):
            missing = [
                n for n, vc in zip(self.names, self.compasses, strict=True) if not vc.is_learned
            ]
            raise NotLearnedError(f"spots without a learned map: {missing}")
        which = self._spot_indices(spots)
        raw, ests = self._scores_of(image, camera, which, every=spots is None, gain=gain)
        rel = raw - self._home_scores_of(np.array([e.heading_deg for e in ests]), which)
        logw = self.sharpness * rel
        w = np.exp(logw - logw.max())
        w /= w.sum()
        pos = w @ self.positions[which]
        names = [self.names[k] for k in which]
        return AtlasEstimate(
            position=(float(pos[0]), float(pos[1])),
            goodness={n: float(math.exp(r)) for n, r in zip(names, rel, strict=True)},
            weights={n: float(v) for n, v in zip(names, w, strict=True)},
            estimates=dict(zip(names, ests, strict=True)),
        )

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | os.PathLike, metadata: Mapping[str, object] | None = None) -> Path:
        """Save every spot's map, the spot layout and the home normalisation, atomically.

        One ``.npz`` file (no pickling); colour classes shared by all spots are stored
        once. ``metadata`` (JSON-serialisable: how the atlas was learned) is kept with
        it and returned by :meth:`load_with_metadata`.

        Returns
        -------
        pathlib.Path
            The path written (``.npz`` appended if missing).
        """
        shared = all(vc.colors is self.compasses[0].colors for vc in self.compasses)
        header = {
            "names": list(self.names),
            "positions": self.positions.tolist(),
            "home": self.home,
            "home_position": list(self.home_position),
            "sharpness": self.sharpness,
            "is_normalized": self.is_normalized,
            "kappa": self._kappa,
            "shared_colors": shared,
            "metadata": dict(metadata or {}),
        }
        arrays: dict[str, np.ndarray] = {
            "atlas": json_array(header),
            "home_scores": self._home_scores.astype(np.float64),
            "home_headings": self._home_headings.astype(np.float64),
        }
        if shared:
            if self.compasses[0].colors is None:
                raise NotLearnedError("nothing to save: the compasses have no colour classes")
            arrays.update(self.compasses[0].colors.to_arrays())
        for i, vc in enumerate(self.compasses):
            for key, a in vc.to_arrays(with_colors=not shared).items():
                arrays[f"spot{i}/{key}"] = a
        if self.landmarks is not None:
            arrays.update(self.landmarks.to_arrays())
        return save_npz_atomic(path, ATLAS_SCHEMA, ATLAS_SCHEMA_VERSION, arrays)

    @classmethod
    def load(cls, path: str | os.PathLike) -> CompassAtlas:
        """Load an atlas written by :meth:`save` (see :meth:`load_with_metadata`)."""
        return cls.load_with_metadata(path)[0]

    @classmethod
    def load_with_metadata(cls, path: str | os.PathLike) -> tuple[CompassAtlas, dict]:
        """Load an atlas written by :meth:`save` and the metadata saved with it.

        Raises
        ------
        MapFileError
            Missing, empty or corrupt file, another schema or version, or any entry
            that does not match the header (the message names the file and entry).
        """
        arrays = load_npz_checked(path, ATLAS_SCHEMA, ATLAS_SCHEMA_VERSION)
        header = read_json_array(arrays, "atlas", path)
        try:
            names = [str(n) for n in header["names"]]
            positions = [(float(x), float(y)) for x, y in header["positions"]]
            home = str(header["home"])
            hx, hy = (float(v) for v in header["home_position"])
            sharpness = float(header["sharpness"])
            normalized = header["is_normalized"]
            kappa = float(header["kappa"])
            shared = header["shared_colors"]
            metadata = header["metadata"]
        except (KeyError, TypeError, ValueError) as e:
            raise MapFileError(f"{path}: invalid atlas header ({type(e).__name__}: {e})") from None
        if not 1 <= len(names) <= MAX_SPOTS or len(positions) != len(names):
            raise MapFileError(
                f"{path}: header declares {len(names)} spots and {len(positions)} positions "
                f"(1 to {MAX_SPOTS} spots, one position each)"
            )
        if len(set(names)) != len(names):
            raise MapFileError(f"{path}: header repeats a spot name")
        if not isinstance(normalized, bool) or not isinstance(shared, bool):
            raise MapFileError(f"{path}: is_normalized and shared_colors must be booleans")
        # one config for every spot, and the memory its maps will claim, before any map
        # is built (CompassAtlas checks both again with the compasses it is given)
        raws = [read_json_array(arrays, f"spot{i}/config", path) for i in range(len(names))]
        if any(r != raws[0] for r in raws):
            raise MapFileError(f"{path}: the spots' maps do not share one config")
        try:
            config = CompassConfig.from_dict(raws[0])  # type: ignore[arg-type]
            _check_atlas_size(config, len(names), 1 if shared else len(names))
        except (TypeError, ValueError) as e:
            raise MapFileError(f"{path}: invalid config ({e})") from None
        if not isinstance(metadata, dict):
            raise MapFileError(f"{path}: metadata must be a JSON object")
        colors = None
        if shared:
            try:
                colors = ColorClasses.from_arrays(arrays)
            except ValueError as e:
                raise MapFileError(f"{path}: invalid colour classes ({e})") from None
        spots = {}
        for i, (name, pos) in enumerate(zip(names, positions, strict=True)):
            prefix = f"spot{i}/"
            sub = {k[len(prefix) :]: a for k, a in arrays.items() if k.startswith(prefix)}
            vc = VisualCompass.from_arrays(sub, f"{path} (spot {name!r})", colors=colors)
            spots[name] = (pos, vc)
        try:
            atlas = cls(spots, home=home, home_position=(hx, hy), sharpness=sharpness)
        except ValueError as e:
            raise MapFileError(f"{path}: {e}") from None
        n = len(names)
        scores, headings = arrays.get("home_scores"), arrays.get("home_headings")
        for key, a in (("home_scores", scores), ("home_headings", headings)):
            if a is None or a.ndim != 2 or a.shape[1] != n or a.dtype.kind != "f":
                raise MapFileError(f"{path}: entry {key!r} missing or not a (frames, {n}) array")
            if not np.all(np.isfinite(a)):
                raise MapFileError(f"{path}: entry {key!r} is not finite")
        if scores.shape != headings.shape or (normalized and scores.shape[0] == 0):
            raise MapFileError(f"{path}: home normalisation entries do not match")
        lo, hi = _kappa_of(MAX_KERNEL_DEG), _kappa_of(MIN_KERNEL_DEG)
        if not (math.isfinite(kappa) and lo <= kappa <= hi):
            raise MapFileError(
                f"{path}: kernel concentration kappa={kappa} is outside [{lo:.4g}, {hi:.4g}] "
                f"(kernel widths {MIN_KERNEL_DEG:g}-{MAX_KERNEL_DEG:g}°)"
            )
        atlas._home_scores = scores.astype(np.float64)
        atlas._home_headings = headings.astype(np.float64)
        atlas._kappa = kappa
        atlas.is_normalized = normalized
        if any(k.startswith("landmarks/") for k in arrays):
            try:
                atlas.landmarks = LandmarkMap.from_arrays(arrays, config.n_colors)
            except ValueError as e:
                raise MapFileError(f"{path}: {e}") from None
        return atlas, metadata


def _kappa_of(kernel_deg: float) -> float:
    """Concentration of the home normalisation's von Mises kernel of width ``kernel_deg``."""
    return 1.0 / math.radians(kernel_deg) ** 2


def _check_atlas_size(config: CompassConfig, n_spots: int, n_color_sets: int) -> None:
    """A ``ValueError`` unless ``n_spots`` maps of ``config`` with ``n_color_sets``
    colour lookup tables fit in :data:`MAX_ATLAS_BYTES` (:meth:`CompassConfig.memory_bytes`
    reckons with one table) and there are at most :data:`MAX_SPOTS` of them."""
    if n_spots > MAX_SPOTS:
        raise ValueError(f"an atlas holds at most {MAX_SPOTS} spots, got {n_spots}")
    tables = (n_color_sets - 1) * 2 ** (3 * config.lut_bits)
    need = config.memory_bytes(n_maps=n_spots) + tables
    if need > MAX_ATLAS_BYTES:
        raise ValueError(
            f"{n_spots} maps of this config would need about {need / 2**20:.0f} MiB to load "
            f"and score one frame, more than MAX_ATLAS_BYTES = {MAX_ATLAS_BYTES / 2**20:.0f} "
            "MiB: use fewer spots or a smaller CompassConfig"
        )
