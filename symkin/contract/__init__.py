"""The bottom layer: what the generated code and the runtime must agree on, defined once.

Options and their defaults per real type (options), the solver's status codes (status), the
fixed numbers of the condition estimator, the error model and Newton's tightening (tuning),
the manifest's file name and keys (manifest), the suffixes naming a rate and an
acceleration in every column and symbol (columns), and the plain dense Newton and
Levenberg-Marquardt both the runtime and the generation-time sample use (dense_solvers).
Templates render these values from here; nothing in a template repeats one. It imports
nothing of symkin's stages (spec, symbolic, codegen, build, runtime, ...): only the standard
library, NumPy and SciPy.
"""
