"""The loads of a solved run: drivers' efforts and joints' reactions from the kernel's
multipliers (forces), and where rows were removed as redundant, which loads are determinate and
the minimum-norm multipliers of the rest (indeterminate).

The bottom room of the runtime: it imports no other. NumPy only.
"""
