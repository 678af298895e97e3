"""Video of a run: offscreen rendering (EGL by default, see :mod:`sim.gl_backend`) and MP4 files.

:mod:`.render` poses a scene and draws its frames (:class:`.render.VideoRecorder` is the recorder that
``run --video`` and ``replay --video`` share); :mod:`.look` is the frame's look (colours, lights, the ground
past the floor, the follow camera), :mod:`.caption` the title bar and time on each frame, :mod:`.file` the
MP4 writer.  Nothing here touches physics or a log's bytes.
"""
