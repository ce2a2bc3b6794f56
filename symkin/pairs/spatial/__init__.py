"""The spatial pair and driver types (``space: 3d``), one module each, built from the few
basic constraints of :mod:`symkin.pairs.spatial.basic`; listed in :mod:`symkin.pairs`."""
