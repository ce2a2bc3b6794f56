"""The kinematic solve, point by point along the time grid: Newton with its condition estimate
and error model (newton, linalg, accuracy), step subdivision and the passage of singular and
limit configurations (edges), the assembly at t0 (assembly) and the check of the start (start),
the scale-free unit (units), the grid loop of the generated C solver (c_loop), the arrays a
solve writes (result_arrays), and what a run hands back or raises, with its messages
(run_outcome, failures).

Below it only the runtime's protocol; it reads the outputs' Trajectory and the loads' Forces to
hand a run's rows back. Imports NumPy and SciPy only.
"""
