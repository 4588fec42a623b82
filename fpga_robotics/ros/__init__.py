"""ROS 2 and Foxglove without a ROS installation (docs/ros.md).

``bag_writer`` writes a run as a ROS 2 bag (``--bag``), ``bag_source`` reads a bag's images
as the design's input (``--source bag:``), ``foxglove_live`` serves the run's topics and takes
live control from Foxglove (``--live``), ``interactive`` takes it from the terminal
(``--interactive``), ``controls`` applies, logs and replays those inputs
(``--replay-inputs``). ``messages`` builds the standard messages all of them share.
"""
