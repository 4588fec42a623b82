"""What a closed-loop run measured and the scenario's checks against it: the summary and the
verdict (``summary.py``), the sensor designs' metrics (``sensor_metrics.py``)."""
