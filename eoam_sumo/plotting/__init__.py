"""Plots (matplotlib on the Agg canvas): runs, batches and the offline tables.

Only the modules of this package import matplotlib; the core modules never do.
"""
