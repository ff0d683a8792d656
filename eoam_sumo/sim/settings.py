"""The settings of one co-simulation run."""

DEFAULT_MAX_TIME_S = 60.0  # simulated time limit of a run [s]
