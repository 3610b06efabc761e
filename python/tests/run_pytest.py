"""Runs the Python package's tests with pytest (ctest: python_bindings).

Exits 77, which ctest reports as skipped, when NumPy or pytest is missing
(Debian: apt-get install python3-numpy python3-pytest python3-pandas).
"""
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print("python_bindings skipped: %s (apt-get install python3-numpy python3-pytest)" % e)
    sys.exit(77)

sys.exit(pytest.main(["-p", "no:cacheprovider"] + sys.argv[1:]))
