"""The forward-dynamics tests' shared fixture (motion_support)."""

from motion_support import crank_slider, crank_slider_c, crank_slider_system  # noqa: F401
