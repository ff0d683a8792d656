"""Experiment batches: run a matrix's cases in parallel, export results.csv and Table 2."""
