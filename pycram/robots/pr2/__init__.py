"""The PR2: description data and robot-specific modules."""
