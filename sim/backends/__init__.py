"""Simulation backends of ``FollowTarget`` behind one frame-level interface."""
