"""The rerun viewer for closed-loop runs: what the FPGA sees and decides, on one timeline.

``open_recorder(mode, default_path=...)`` returns a ``Recorder``; the closed loop calls
``log_world_map`` once, ``log_frame`` per camera frame and ``close()`` at the end (a line
saying where the recording went). See docs/viewer.md.
"""

from .modes import Mode, parse_mode
from .recorder import Recorder, open_recorder

__all__ = ["Mode", "Recorder", "open_recorder", "parse_mode"]
