"""The SUMO side of the co-simulation: adapter, sensing, geometry, outcome and the step loop."""
