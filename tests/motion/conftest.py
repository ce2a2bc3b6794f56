"""The forward-dynamics tests' shared fixture (motion_support)."""

from motion_support import crank_slider  # noqa: F401
