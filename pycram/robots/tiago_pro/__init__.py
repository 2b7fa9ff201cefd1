"""TIAGo Pro (two 7-DoF arms, omnidirectional base): description data and robot-specific modules."""
