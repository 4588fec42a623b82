"""Benchmarks: a module per subject, each a ``main(argv)`` that prints figures
(``fpga-robotics bench --list``)."""
