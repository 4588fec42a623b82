"""Benchmarks: a module per subject, each declaring its options and its measurement on the
shared scaffold (``scaffold.command``), run as ``fpga-robotics bench WHAT``
(``fpga-robotics bench --list``); ``bench calibrate`` gives the unit that makes the figures
travel between machines."""
