"""What a video of a run is: frame size, frame rate and the default time scale.

Kept apart from :mod:`mjswarm.outputs.video` (which loads MuJoCo and the renderer) so
that the command line can state them in its help without loading either.
"""

#: Frames per second of video.
FPS = 30
#: Default simulated seconds per second of video (a 420 s run lasts 14 s).
DEFAULT_SPEEDUP = 30.0
#: Frame size (pixels).
WIDTH_PX, HEIGHT_PX = 640, 480
