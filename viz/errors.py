"""What the viewer package raises for something the user can fix.

The library never prints: a ``ViewerError`` carries one line saying what is wrong and what to
type instead, and the application (the CLI) shows it. Everything else it must tell the user
(a file it fell back to, where a recording went) comes back as ``Recorder.notices``.
"""

from fpga_robotics.hw.errors import UserError

__all__ = ["ViewerError"]


class ViewerError(UserError):
    """A bad mode string or option, an unusable output path, or a viewer that cannot be used
    with no file to fall back on; the message says what to do instead."""
