"""Baseline solvers for the textbook crank-slider, written by us, run by bench/run_all.py."""
