"""One module per pass kind. Each pass class has ``run(frame, planned_pass)``."""
