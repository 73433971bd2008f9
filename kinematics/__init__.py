"""Pure numpy/scipy kinematics of non-circular-gear planting mechanisms (never imports cadgen)."""
