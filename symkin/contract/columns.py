"""How a quantity's rate and acceleration are named, wherever names meet users: the columns of
a run's CSV (``q_t``, ``q_tt``), of an inputs table (``NAME_t``, ``NAME_tt``) and the symbols
SymPy derives with. Here, at the bottom, so that the command line can read a table without
importing the stages (a warm run loads neither SymPy nor pydantic)."""

RATE_SUFFIXES = ("_t", "_tt")
"""The suffixes of a quantity's rate and of its acceleration, in that order."""

ENERGY_COLUMNS = {"kinetic_energy": "energy.kinetic", "potential_energy": "energy.potential",
                  "work_nonconservative": "energy.work"}
"""A forward-dynamics run's energy arrays: the NPZ name of each and its CSV column."""
