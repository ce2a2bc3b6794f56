"""Sweeps: many parameter sets of one mechanism through the generated batch solver, in this
process, in local processes or on a Dask cluster; and tolerance analysis on top of them.

The entry point is the function ``symkin.sweep`` (:func:`symkin.sweeps.api.sweep`); this
package is named in the plural so that the function's name is not shadowed by it.
"""
