"""The planar pair and driver types of the chapter (2.4), one module each, and the distance
constraint; listed in :mod:`symkin.pairs`."""
