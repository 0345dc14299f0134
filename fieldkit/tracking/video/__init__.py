"""Video -> Track: pixels to world positions and spin (reader, background, detection,
stabilisation, calibration and lens, marker spin).

FFmpeg, OpenCV's video backend, prints its own decoder complaints to stderr
(``[mjpeg @ 0x...] overread 8``); fieldkit reports damaged frames itself, in one line
naming the file and the frames, so FFmpeg is silenced here, before any video is
opened (the level is read when OpenCV first opens a file). A value the user set in
the environment is kept (to debug a codec).
"""

import os

os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")  # AV_LOG_QUIET
os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
