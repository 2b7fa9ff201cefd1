"""TIAGo (one arm): description data and robot-specific modules."""
