"""The duckbill cam: its design from the planting events, checks and contour."""
