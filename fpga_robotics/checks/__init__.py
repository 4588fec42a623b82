"""What a closed-loop run measured and the scenario's checks against it: what a check is
(``check.py``), the shipped checks (``shipped.py``), the registry that holds them and any a
user adds, and the verdict (``registry.py``), the summary (``summary.py``), the sensor
designs' metrics (``sensor_metrics.py``)."""
