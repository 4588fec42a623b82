"""Python models of the designs, written from the docs (not from the RTL): FollowTarget's numpy
golden model (``follow_target.py``), FollowLine's (``follow_line.py``), the ultrasound
driver's and FollowTargetSafe's interlock (``ultrasound_driver.py``)."""
