"""The compass on your own footage: frames from a video or a folder, yaws from a CSV.

A camera turned in place gives a video (or a folder of photos) from which the compass
learns a map (paper 4.3: a full turn at one spot, every frame at its known yaw, eq. 6);
another video of the same place is then tracked frame by frame (eq. 5, 16: the best
heading, its spread, eq. 27, and the goodness of fit, eq. 28).

What is where:

* :mod:`~vc_gym.compass.footage.frames` — :class:`Footage` (a video or a folder of
  images, read one frame at a time), :class:`BadFrameError`, :func:`image_file_size`
  (a size from an image's header), :func:`image_file_problem` (is a file whole?),
  :func:`scaled_size` and the limits :data:`IMAGE_SUFFIXES`, :data:`MAX_FRAME_PIXELS`,
  :data:`MAX_IMAGE_FILE_BYTES`;
* :mod:`~vc_gym.compass.footage.yaws` — :class:`YawTable`, :func:`read_yaw_csv`,
  :func:`footage_yaws` (each frame's yaw) and :data:`MAX_YAW_CSV_BYTES`;
* :mod:`~vc_gym.compass.footage.tracking` — :func:`footage_camera`,
  :func:`learn_footage`, :class:`FootageTrack`, :func:`track_footage`,
  :func:`write_track_csv`, :func:`calibrate_footage`, :data:`Progress`,
  :data:`COLOR_FIT_FRAMES`, :data:`CALIBRATION_FRAMES` and
  :data:`CALIBRATION_MAX_BYTES`;
* :mod:`~vc_gym.compass.footage.video` — :func:`draw_estimate`, :class:`VideoSink` and
  :data:`VIDEO_SUFFIXES`.
"""

from vc_gym.compass.footage.frames import (
    IMAGE_SUFFIXES,
    MAX_FRAME_PIXELS,
    MAX_IMAGE_FILE_BYTES,
    BadFrameError,
    Footage,
    image_file_problem,
    image_file_size,
    scaled_size,
)
from vc_gym.compass.footage.tracking import (
    CALIBRATION_FRAMES,
    CALIBRATION_MAX_BYTES,
    COLOR_FIT_FRAMES,
    FootageTrack,
    Progress,
    calibrate_footage,
    footage_camera,
    learn_footage,
    track_footage,
    write_track_csv,
)
from vc_gym.compass.footage.video import VIDEO_SUFFIXES, VideoSink, draw_estimate
from vc_gym.compass.footage.yaws import MAX_YAW_CSV_BYTES, YawTable, footage_yaws, read_yaw_csv

__all__ = [
    "BadFrameError",
    "CALIBRATION_FRAMES",
    "CALIBRATION_MAX_BYTES",
    "COLOR_FIT_FRAMES",
    "IMAGE_SUFFIXES",
    "MAX_FRAME_PIXELS",
    "MAX_IMAGE_FILE_BYTES",
    "MAX_YAW_CSV_BYTES",
    "Progress",
    "Footage",
    "FootageTrack",
    "VIDEO_SUFFIXES",
    "VideoSink",
    "YawTable",
    "calibrate_footage",
    "draw_estimate",
    "footage_camera",
    "footage_yaws",
    "image_file_problem",
    "image_file_size",
    "learn_footage",
    "read_yaw_csv",
    "scaled_size",
    "track_footage",
    "write_track_csv",
]
