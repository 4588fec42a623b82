"""The rerun viewer for closed-loop runs: what the FPGA sees and decides, on one timeline.

``open_recorder(mode, default_path=...)`` returns a ``Recorder``; the closed loop calls
``log_world_map`` once, ``log_frame`` per camera frame and ``close()`` at the end. The package
never prints: what the user must be told comes back in ``Recorder.notices`` (and from
``close()``), and what the user must fix is raised as ``ViewerError``. See docs/viewer.md.
"""

from .errors import ViewerError
from .modes import Mode, parse_mode
from .recorder import Recorder, open_recorder

__all__ = ["Mode", "Recorder", "ViewerError", "open_recorder", "parse_mode"]
