"""fpga-robotics: Amaranth gateware for vision-guided robots, simulated in closed loop.

Subpackages: ``fpga_robotics.hw`` (gateware), ``fpga_robotics.sim`` (backends, world, camera),
``fpga_robotics.viz`` (rerun viewer).
"""

__version__ = "0.1.0"
